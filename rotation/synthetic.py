"""Synthetic flow fields with exact rotation truth, for tests and benchmarks.

The street model is a ray-cast, piecewise-planar scene in camera-t coordinates
(x right, y down, z forward, metres): a ground plane below the camera, two building
walls along the street, a skyline at infinity beyond them, and people as upright,
fronto-parallel billboards walking with their own velocities.

Between frames the camera turns by R_t and moves by T (camera-t axes), so a static
point X goes to R_t (X - T) in camera t+1, a person's point to R_t (X + V - T), and a
point at infinity along d to R_t d. The flow is the difference of the projections.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rotation import so3
from rotation.camera import intrinsics


def pixel_rays(K: NDArray, size: tuple[int, int]) -> NDArray[np.float64]:
    """K⁻¹ p for every pixel: (H, W, 3) rays with z = 1."""
    h, w = size
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    return np.stack([(xx - K[0, 2]) / K[0, 0], (yy - K[1, 2]) / K[1, 1], np.ones_like(xx)], -1)


def project_flow(K: NDArray, rays: NDArray, X1: NDArray) -> NDArray[np.float32]:
    """Flow from the pixels of ``rays`` to the projections of camera-(t+1) points X1."""
    p0 = rays @ K.T
    p1 = X1 @ K.T
    with np.errstate(divide="ignore", invalid="ignore"):
        flow = p1[..., :2] / p1[..., 2:] - p0[..., :2]
    flow[X1[..., 2] <= 1e-6] = np.nan  # behind the next camera: no correspondence
    return flow.astype(np.float32)


def rotation_flow(
    R: NDArray, focal: float, size: tuple[int, int], center: tuple[float, float] | None = None
) -> NDArray[np.float32]:
    """Exact flow of a pure rotation: p → K R K⁻¹ p."""
    K = intrinsics(focal, size, center)
    rays = pixel_rays(K, size)
    return project_flow(K, rays, rays @ np.asarray(R).T)


@dataclass(frozen=True)
class Street:
    """Geometry of the street, metres."""

    camera_height: float = 1.5
    half_width: float = 6.0
    wall_height: float = 12.0
    length: float = 120.0
    walls: bool = True


@dataclass(frozen=True)
class People:
    """Billboards: centre (x, z) on the ground, width, height, and velocity (3,) per frame."""

    x: NDArray[np.float64]
    z: NDArray[np.float64]
    width: NDArray[np.float64]
    height: NDArray[np.float64]
    velocity: NDArray[np.float64]


def random_people(rng: np.random.Generator, n: int, street: Street, fps: float = 30.0) -> People:
    """n pedestrians 3–30 m ahead, walking at 0.8–1.8 m/s along or across the street."""
    heading = rng.uniform(0, 2 * np.pi, n)
    speed = rng.uniform(0.8, 1.8, n) / fps
    velocity = np.stack([np.sin(heading) * speed, np.zeros(n), np.cos(heading) * speed], -1)
    return People(
        x=rng.uniform(-street.half_width + 0.5, street.half_width - 0.5, n),
        z=rng.uniform(3.0, 30.0, n),
        width=rng.uniform(0.45, 0.65, n),
        height=rng.uniform(1.55, 1.9, n),
        velocity=velocity,
    )


def street_flow(
    R: NDArray,
    T: NDArray,
    focal: float,
    size: tuple[int, int],
    street: Street = Street(),
    people: People | None = None,
) -> NDArray[np.float32]:
    """Exact forward flow of the street scene under rotation R and translation T."""
    K = intrinsics(focal, size)
    rays = pixel_rays(K, size)
    dx, dy = rays[..., 0], rays[..., 1]
    depth = np.full(size, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        ground = np.where(dy > 0, street.camera_height / dy, np.inf)
        ground[np.abs(ground * dx) > street.half_width] = np.inf
        depth = np.minimum(depth, ground)
        if street.walls:
            wall = np.where(dx != 0, street.half_width / np.abs(dx), np.inf)
            height = street.camera_height - wall * dy  # metres above the ground
            wall[(height < 0) | (height > street.wall_height)] = np.inf
            depth = np.minimum(depth, wall)
    depth[depth > street.length] = np.inf

    motion = np.zeros((*size, 3))
    if people is not None:
        # Far people first, so nearer ones overwrite them where they overlap.
        for i in np.argsort(-people.z):
            z = people.z[i]
            x, y = dx * z, dy * z
            hit = (
                (np.abs(x - people.x[i]) <= people.width[i] / 2)
                & (y <= street.camera_height)
                & (y >= street.camera_height - people.height[i])
                & (z < depth)
            )
            depth[hit] = z
            motion[hit] = people.velocity[i]

    finite = np.isfinite(depth)
    X1 = np.where(finite[..., None], rays * np.where(finite, depth, 0)[..., None], rays)
    X1 = X1 + np.where(finite[..., None], motion - np.asarray(T), 0.0)
    return project_flow(K, rays, X1 @ np.asarray(R).T)


def corrupt(
    rng: np.random.Generator,
    flow: NDArray,
    noise_px: float = 0.0,
    gross_fraction: float = 0.0,
    gross_px: float = 20.0,
) -> NDArray[np.float32]:
    """Add Gaussian noise, and replace a fraction of vectors by uniform random flow."""
    out = flow + rng.normal(scale=noise_px, size=flow.shape) if noise_px > 0 else flow.copy()
    if gross_fraction > 0:
        bad = rng.random(flow.shape[:2]) < gross_fraction
        out[bad] = rng.uniform(-gross_px, gross_px, size=(int(bad.sum()), 2))
    return out.astype(np.float32)


@dataclass(frozen=True)
class FlowSet:
    """A benchmark set: flows (N, H, W, 2) with their true rotations R_t (N, 3, 3)."""

    name: str
    flows: NDArray[np.float32]
    rotations: NDArray[np.float64]
    focal: float


SCENARIOS = {
    # name: (people, noise px, gross-error fraction, scene)
    "pure": (0, 0.0, 0.0, False),
    "outliers": (0, 0.5, 0.6, False),
    "street": (12, 0.4, 0.1, True),
    "crowd": (30, 0.6, 0.2, True),
}


def make_set(
    name: str,
    n: int,
    *,
    seed: int = 0,
    size: tuple[int, int] = (270, 480),
    focal: float = 413.75,
    max_deg: float = 2.0,
    min_deg: float = 0.0,
) -> FlowSet:
    """One of :data:`SCENARIOS` with n random rotations up to ``max_deg``.

    Street and crowd scenes walk forward about 3.5 cm per frame with a few mm of
    sideways sway and vertical bob, as a handheld camera does at walking pace.
    """
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario {name!r}; choose from {sorted(SCENARIOS)}")
    n_people, noise, gross, scene = SCENARIOS[name]
    rng = np.random.default_rng(seed)
    rotations = so3.random_rotations(rng, n, max_deg, min_deg)
    flows = np.empty((n, *size, 2), np.float32)
    for i, R in enumerate(rotations):
        if scene:
            T = np.array([rng.normal(0, 0.004), rng.normal(0, 0.002), rng.normal(0.035, 0.005)])
            people = random_people(rng, n_people, Street())
            clean = street_flow(R, T, focal, size, Street(), people)
        else:
            clean = rotation_flow(R, focal, size)
        flows[i] = corrupt(rng, clean, noise, gross)
    return FlowSet(name, flows, rotations, focal)
