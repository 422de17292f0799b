"""Procedural textures and the far background, deterministic for a seed.

The background is looked up by viewing direction. It is the real 360° cube map
``meadow_cube.jpg`` when given (six 2048² faces stacked +X, -X, +Y, -Y, +Z, -Z, with +Y
the sky), otherwise a procedural skyline panorama.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

PX_PER_M = 100.0  # texture resolution of the ground and the walls
TILE_M = 10.24  # their textures repeat every 1024 px


def _noise(rng: np.random.Generator, h: int, w: int, scales=(1.0, 3.0, 9.0)) -> NDArray:
    """Multi-scale blurred noise in [0, 1], tileable (wrapped blur)."""
    img = np.zeros((h, w), np.float32)
    for s in scales:
        n = rng.normal(size=(h, w)).astype(np.float32)
        m = min(int(3 * s) + 1, h, w)  # blur a wrapped copy, so the result tiles
        padded = np.pad(n, m, mode="wrap")
        img += cv2.GaussianBlur(padded, (0, 0), s)[m:-m, m:-m] * s
    img -= img.min()
    return img / max(img.max(), 1e-6)


def ground_texture(rng: np.random.Generator) -> NDArray[np.uint8]:
    """Grey paving slabs with grime: 1024² covering 10.24 m, tileable."""
    n = _noise(rng, 1024, 1024)
    base = 95 + 70 * n
    yy, xx = np.mgrid[0:1024, 0:1024]
    joints = ((xx % 64) < 3) | (((yy + 32 * ((xx // 64) % 2)) % 128) < 3)
    base[joints] *= 0.55
    tint = np.array([1.0, 0.97, 0.92], np.float32)
    return np.clip(base[..., None] * tint, 0, 255).astype(np.uint8)


def facade_texture(rng: np.random.Generator) -> NDArray[np.uint8]:
    """A building front: rendered plaster with rows of windows, 1024² per 10.24 m."""
    n = _noise(rng, 1024, 1024, (1.0, 4.0))
    colour = rng.uniform(110, 210, 3).astype(np.float32)
    img = colour * (0.75 + 0.5 * n[..., None])
    yy, xx = np.mgrid[0:1024, 0:1024]
    windows = ((xx % 256) > 60) & ((xx % 256) < 190) & ((yy % 320) > 80) & ((yy % 320) < 250)
    glass = 40 + 80 * _noise(rng, 1024, 1024, (2.0, 8.0))
    img[windows] = glass[windows, None] * np.array([0.8, 0.9, 1.0])
    frames = windows ^ cv2.dilate(windows.astype(np.uint8), np.ones((9, 9))).astype(bool)
    img[frames] = 235
    return np.clip(img, 0, 255).astype(np.uint8)


def person_sprite(rng: np.random.Generator) -> NDArray[np.uint8]:
    """An RGBA figure 64×224: head, coat, legs, with cloth texture; alpha 0 outside."""
    h, w = 224, 64
    img = np.zeros((h, w, 4), np.float32)
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    cloth = 0.7 + 0.6 * _noise(rng, h, w, (1.0, 2.5))[..., None]
    coat = rng.uniform(30, 230, 3) * cloth
    trousers = rng.uniform(20, 120, 3) * cloth
    skin = rng.uniform([150, 100, 70], [240, 200, 170]) * (0.9 + 0.2 * cloth)
    head = (xx - 32) ** 2 / 14**2 + (yy - 20) ** 2 / 18**2 < 1
    body = (np.abs(xx - 32) < 24 - 4 * (yy - 40) / 80) & (yy >= 38) & (yy < 125)
    legs = (np.abs(np.abs(xx - 32) - 10) < 8) & (yy >= 120)
    for mask, colour in ((legs, trousers), (body, coat), (head, skin)):
        img[mask, :3] = colour[mask]
        img[mask, 3] = 255
    return img.astype(np.uint8)


@dataclass(frozen=True)
class Background:
    """Far scenery, looked up by world direction (x right, y down, z forward)."""

    texture: NDArray[np.uint8]
    kind: str  # "cube" or "panorama"

    def coords(self, d: NDArray) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """Texture coordinates (map_x, map_y) for directions d (..., 3)."""
        if self.kind == "cube":
            return _cube_coords(d, self.texture.shape[1])
        h, w = self.texture.shape[:2]
        azimuth = np.arctan2(d[..., 0], d[..., 2])
        elevation = np.arctan2(-d[..., 1], np.hypot(d[..., 0], d[..., 2]))
        mx = (azimuth / (2 * np.pi) + 0.5) * w
        my = (0.5 - elevation / np.pi) * h
        return mx.astype(np.float32), my.astype(np.float32)


def _cube_coords(d: NDArray, face: int) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    # OpenGL cube-map convention, in y-up axes.
    x, y, z = d[..., 0], -d[..., 1], d[..., 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    index = np.where(
        (ax >= ay) & (ax >= az),
        np.where(x > 0, 0, 1),
        np.where(ay >= az, np.where(y > 0, 2, 3), np.where(z > 0, 4, 5)),
    )
    ma = np.choose(index, [ax, ax, ay, ay, az, az])
    sc = np.choose(index, [-z, z, x, x, x, -x])
    tc = np.choose(index, [-y, -y, z, -z, -y, -y])
    u = (sc / ma + 1) * 0.5 * (face - 1)
    v = (tc / ma + 1) * 0.5 * (face - 1) + index * face
    return u.astype(np.float32), v.astype(np.float32)


def skyline(rng: np.random.Generator, width: int = 4096) -> NDArray[np.uint8]:
    """An equirectangular panorama: sky with clouds, a city skyline on the horizon."""
    h = width // 2
    yy = np.arange(h, dtype=np.float32)[:, None] / h
    sky = np.stack([120 + 100 * yy, 160 + 70 * yy, 235 + 0 * yy], -1) * np.ones((1, width, 1))
    clouds = _noise(rng, h, width, (4.0, 16.0, 40.0))
    sky += 90 * np.clip(clouds - 0.5, 0, 1)[..., None]
    horizon = h // 2
    x = 0
    while x < width:
        bw = int(rng.integers(40, 160))
        top = horizon - int(rng.integers(20, 260))
        colour = rng.uniform(60, 200, 3)
        block = sky[top:horizon, x : x + bw]
        n = _noise(rng, *block.shape[:2], (1.0,)) if block.size else 0
        block[:] = colour * (0.8 + 0.3 * np.asarray(n)[..., None])
        block[
            (np.arange(block.shape[0]) % 24 < 10)[:, None] & (np.arange(block.shape[1]) % 16 < 8)
        ] *= 0.6
        x += bw
    sky[horizon:] = 90 + 60 * _noise(rng, h - horizon, width)[..., None]
    return np.clip(sky, 0, 255).astype(np.uint8)


def load_background(path: Path | None, rng: np.random.Generator, width: int = 4096) -> Background:
    """The cube-map photograph at ``path`` if given, else the procedural skyline
    ``width`` pixels around."""
    if path is not None:
        img = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if img is None or img.shape[0] != 6 * img.shape[1]:
            raise ValueError(f"{path} is not a cube map of six square faces stacked vertically")
        return Background(img[..., ::-1].copy(), "cube")
    return Background(skyline(rng, width), "panorama")


def mip_chain(texture: NDArray[np.uint8], levels: int = 4) -> list[NDArray[np.uint8]]:
    """The texture and its successive 2× area-averaged reductions."""
    chain = [texture]
    for _ in range(levels - 1):
        t = chain[-1]
        chain.append(
            cv2.resize(t, (t.shape[1] // 2, t.shape[0] // 2), interpolation=cv2.INTER_AREA)
        )
    return chain
