"""A piecewise-planar street, ray-cast per pixel, with exact ground-truth flow.

World axes are the first frame's camera axes (x right, y down, z forward, metres).
The ground is the plane y = ``camera_height`` (:class:`rotation.synthetic.Street`, the
street of the estimator's synthetic flows, drawn 150 m long here); optional building
fronts are the planes x = ±``half_width`` up to ``wall_height``; people are upright
billboards facing the street's axis (planes z = const) that walk with their own
velocities; everything else is far background, seen by direction only.

Each pixel's ray is intersected with every surface and the nearest hit is kept, so
occlusion is exact. Texture lookups use a small mip chain chosen per pixel from its
footprint, which keeps the distant ground from shimmering.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from rotation.synthetic import Street
from stabilize.synth.textures import (
    PX_PER_M,
    Background,
    facade_texture,
    ground_texture,
    mip_chain,
    person_sprite,
)

N_SPRITES = 8


@dataclass(frozen=True)
class Crowd:
    """People: feet at (x, z) at time 0, velocity (vx, vz) m/s, size, sprite index."""

    x: NDArray
    z: NDArray
    vx: NDArray
    vz: NDArray
    width: NDArray
    height: NDArray
    sprite: NDArray

    def __len__(self) -> int:
        return len(self.x)


def random_crowd(rng: np.random.Generator, n: int, street: Street, reach_m: float) -> Crowd:
    """n pedestrians within ``reach_m`` ahead, walking along or across the street."""
    along = rng.random(n) < 0.75
    speed = rng.uniform(0.8, 1.8, n)
    sign = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    return Crowd(
        x=rng.uniform(-street.half_width + 0.6, street.half_width - 0.6, n),
        z=rng.uniform(3.0, max(reach_m, 8.0), n),
        vx=np.where(along, 0.0, sign * speed),
        vz=np.where(along, sign * speed, 0.0),
        width=rng.uniform(0.5, 0.65, n),
        height=rng.uniform(1.6, 1.9, n),
        sprite=rng.integers(0, N_SPRITES, n),
    )


@dataclass
class Scene:
    street: Street
    crowd: Crowd
    background: Background
    ground: list[NDArray]
    facade: list[NDArray]
    sprites: list[NDArray]

    @classmethod
    def build(
        cls, rng: np.random.Generator, street: Street, crowd: Crowd, background: Background
    ) -> Scene:
        return cls(
            street,
            crowd,
            background,
            mip_chain(ground_texture(rng)),
            mip_chain(facade_texture(rng)),
            [person_sprite(rng) for _ in range(N_SPRITES)],
        )


@dataclass
class Hits:
    """What each pixel sees: colour; depth along its world ray d from the camera centre
    o (inf: background); and the velocity of what was hit."""

    colour: NDArray[np.uint8]
    depth: NDArray[np.float64]
    direction: NDArray[np.float64]
    origin: NDArray[np.float64]
    velocity: NDArray[np.float32]


def _lookup(tex: NDArray, u: NDArray, v: NDArray, border: int) -> NDArray:
    """Bilinear texture samples at flat texel coordinates (N,) → (N, channels)."""
    n = len(u)
    rows = -(-n // 1024)  # remap wants 2-D maps below 32767 on a side

    def as_map(a: NDArray) -> NDArray[np.float32]:
        out = np.zeros(rows * 1024, np.float32)
        out[:n] = a
        return out.reshape(rows, 1024)

    got = cv2.remap(tex, as_map(u), as_map(v), cv2.INTER_LINEAR, borderMode=border)
    return got.reshape(rows * 1024, -1)[:n]


def _paint(
    flat: NDArray, idx: NDArray, levels: list[NDArray], u: NDArray, v: NDArray, texels: NDArray
) -> None:
    """flat[idx] ← wrapped lookups at texels (u, v), each from the mip level that suits
    its footprint (``texels`` texture pixels per image pixel)."""
    level = _mip_level(texels, len(levels))
    for k, tex in enumerate(levels):
        sel = level == k
        if sel.any():
            scale = 0.5**k
            flat[idx[sel]] = _lookup(tex, u[sel] * scale, v[sel] * scale, cv2.BORDER_WRAP)


def _mip_level(texels_per_px: NDArray, n_levels: int) -> NDArray:
    return np.clip(np.round(np.log2(np.maximum(texels_per_px, 1.0))), 0, n_levels - 1).astype(int)


def _person_box(scene: Scene, i: int, C, c, t, rays) -> tuple[slice, slice] | None:
    """Rows and columns that person i can cover in this frame (None: not in view).

    The billboard's corners, at the first and last row's time and pose, are projected
    and boxed with a margin; only pixels inside the box are ray-cast against it.
    """
    cr, st = scene.crowd, scene.street
    h, w = rays.shape[:2]
    xs, ys = [], []
    for row in (0, h - 1):
        zp = cr.z[i] + cr.vz[i] * t[row]
        xp = cr.x[i] + cr.vx[i] * t[row]
        for dx in (-0.5, 0.5):
            for y in (st.camera_height, st.camera_height - cr.height[i]):
                X = C[row].T @ (np.array([xp + dx * cr.width[i], y, zp]) - c[row])
                if X[2] < 0.05:
                    return (slice(0, h), slice(0, w)) if X[2] > -1.0 else None
                xs.append(X[0] / X[2])
                ys.append(X[1] / X[2])
    fx = 1.0 / (rays[0, 1, 0] - rays[0, 0, 0])  # rays are K⁻¹p: one pixel is 1/f
    cx, cy = -rays[0, 0, 0] * fx, -rays[0, 0, 1] * fx
    x0, x1 = int(min(xs) * fx + cx) - 2, int(max(xs) * fx + cx) + 3
    y0, y1 = int(min(ys) * fx + cy) - 2, int(max(ys) * fx + cy) + 3
    x0, x1, y0, y1 = max(x0, 0), min(x1, w), max(y0, 0), min(y1, h)
    if x0 >= x1 or y0 >= y1:
        return None
    return slice(y0, y1), slice(x0, x1)


@dataclass(frozen=True)
class _Canvas:
    """One frame being painted: world ray directions d (H, W, 3) from origins o (H, 1, 3),
    and the nearest hit so far per pixel (depth along d, colour, velocity)."""

    d: NDArray
    o: NDArray
    depth: NDArray
    colour: NDArray
    velocity: NDArray
    focal: float

    @property
    def flat_d(self) -> NDArray:
        return self.d.reshape(-1, 3)

    def origins(self, idx: NDArray) -> NDArray:
        """The ray origin of each flat pixel index."""
        return self.o.reshape(-1, 3)[idx // self.d.shape[1]]

    def footprint(self, idx: NDArray, s: NDArray, axis: int) -> NDArray:
        """Texels per pixel on a plane whose normal is world axis ``axis``."""
        dd = self.flat_d[idx]
        n = np.linalg.norm(dd, axis=1)
        grazing = np.maximum(np.abs(dd[:, axis]) / n, 0.02)
        return PX_PER_M * s * n / self.focal / np.sqrt(grazing)


def cast(scene: Scene, rays: NDArray, C: NDArray, c: NDArray, t: NDArray, focal: float) -> Hits:
    """Render one frame.

    Args:
        rays: camera rays K⁻¹p, (H, W, 3).
        C: camera-to-world rotation per row, (H, 3, 3) (rows differ under rolling shutter).
        c: camera centre per row, (H, 3).
        t: time per row, (H,), for the walking people.
        focal: focal length in pixels (texture footprint).
    """
    if np.all(C == C[:1]):  # global shutter: one rotation for every row
        d = rays @ C[0].T.astype(rays.dtype)
    else:
        d = np.einsum("hij,hwj->hwi", C, rays)  # world directions, (H, W, 3)
    h, w = d.shape[:2]
    canvas = _Canvas(
        d,
        c[:, None, :],
        np.full((h, w), np.inf),
        np.zeros((h, w, 3), np.uint8),
        np.zeros((h, w, 3), np.float32),
        focal,
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        _cast_ground(scene, canvas)
        for side in (-1.0, 1.0) if scene.street.walls else ():
            _cast_wall(scene, canvas, side)
        _cast_people(scene, canvas, rays, C, c, t)
    # The far background, only where nothing nearer was hit.
    idx = np.flatnonzero(np.isinf(canvas.depth))
    if idx.size:
        mx, my = scene.background.coords(canvas.flat_d[idx])
        flat_colour = canvas.colour.reshape(-1, 3)
        flat_colour[idx] = _lookup(scene.background.texture, mx, my, cv2.BORDER_WRAP)
    return Hits(canvas.colour, canvas.depth, d, canvas.o, canvas.velocity)


def _cast_ground(scene: Scene, cv: _Canvas) -> None:
    """The ground, y = camera_height, up to the street's length and between its walls."""
    st, d, o = scene.street, cv.d, cv.o
    s = np.where(d[..., 1] > 1e-9, (st.camera_height - o[..., 1]) / d[..., 1], np.inf)
    s[s * d[..., 2] + o[..., 2] > st.length] = np.inf
    if st.walls:
        s[np.abs(o[..., 0] + s * d[..., 0]) > st.half_width] = np.inf
    idx = np.flatnonzero(np.isfinite(s))
    if idx.size:
        sf = s.ravel()[idx]
        oo = cv.origins(idx)
        x = oo[:, 0] + sf * cv.flat_d[idx, 0]
        z = oo[:, 2] + sf * cv.flat_d[idx, 2]
        flat_colour = cv.colour.reshape(-1, 3)
        _paint(flat_colour, idx, scene.ground, x * PX_PER_M, z * PX_PER_M, cv.footprint(idx, sf, 1))
        cv.depth.ravel()[idx] = sf


def _cast_wall(scene: Scene, cv: _Canvas, side: float) -> None:
    """A building front, x = side · half_width, from the ground up to wall_height."""
    st, d, o = scene.street, cv.d, cv.o
    s = np.where(side * d[..., 0] > 1e-9, (side * st.half_width - o[..., 0]) / d[..., 0], np.inf)
    idx = np.flatnonzero(s < cv.depth)
    if not idx.size:
        return
    sf = s.ravel()[idx]
    oo = cv.origins(idx)
    y = oo[:, 1] + sf * cv.flat_d[idx, 1]
    z = oo[:, 2] + sf * cv.flat_d[idx, 2]
    keep = (y <= st.camera_height) & (y >= st.camera_height - st.wall_height) & (z <= st.length)
    idx, sf, y, z = idx[keep], sf[keep], y[keep], z[keep]
    u, v = (z * side + 1000.0) * PX_PER_M, (y - st.camera_height) * PX_PER_M + 4096
    _paint(cv.colour.reshape(-1, 3), idx, scene.facade, u, v, cv.footprint(idx, sf, 0))
    cv.depth.ravel()[idx] = sf


def _cast_people(
    scene: Scene, cv: _Canvas, rays: NDArray, C: NDArray, c: NDArray, t: NDArray
) -> None:
    """People: planes z = zp(t), nearest last so that they overwrite farther ones."""
    st, cr = scene.street, scene.crowd
    for i in np.argsort(-cr.z):
        box = _person_box(scene, i, C, c, t, rays)
        if box is None:
            continue
        r, k = box
        zp = cr.z[i] + cr.vz[i] * t[r]
        xp = cr.x[i] + cr.vx[i] * t[r]
        dd, oo = cv.d[r, k], cv.o[r]
        s = (zp[:, None] - oo[..., 2]) / dd[..., 2]
        x = oo[..., 0] + s * dd[..., 0] - xp[:, None]
        y = oo[..., 1] + s * dd[..., 1]
        inside = (s > 0.05) & (np.abs(x) < cr.width[i] / 2)
        feet = st.camera_height
        inside &= (y < feet) & (y > feet - cr.height[i]) & (s < cv.depth[r, k])
        if not inside.any():
            continue
        sprite = scene.sprites[cr.sprite[i]]
        sh, sw = sprite.shape[:2]
        u = ((x / cr.width[i] + 0.5) * sw).astype(np.float32)
        v = ((y - feet + cr.height[i]) / cr.height[i] * sh).astype(np.float32)
        got = cv2.remap(sprite, u, v, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
        sel = inside & (got[..., 3] > 127)
        np.copyto(cv.colour[r, k], got[..., :3], where=sel[..., None])
        np.copyto(cv.depth[r, k], s, where=sel)
        np.copyto(cv.velocity[r, k], np.float32([cr.vx[i], 0.0, cr.vz[i]]), where=sel[..., None])


def ground_truth_flow(
    hits: Hits, K: NDArray, O_next: NDArray, c_next: NDArray, dt: float
) -> NDArray[np.float32]:
    """Exact forward flow to a global-shutter camera (O_next, c_next) dt seconds later."""
    h, w = hits.depth.shape
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    finite = np.isfinite(hits.depth)[..., None]
    point = hits.origin + np.where(finite, hits.depth[..., None], 0.0) * hits.direction
    X = np.where(finite, point + hits.velocity * dt - c_next, hits.direction)
    p = (X @ O_next.T) @ K.T
    with np.errstate(divide="ignore", invalid="ignore"):
        flow = np.stack([p[..., 0] / p[..., 2] - xx, p[..., 1] / p[..., 2] - yy], -1)
    flow[p[..., 2] <= 1e-6] = np.nan
    return flow.astype(np.float32)
