from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest


def texture(h: int, w: int, seed: int = 0) -> np.ndarray:
    """A smooth random RGB texture: blurred noise, with structure at several scales."""
    rng = np.random.default_rng(seed)
    img = np.zeros((h, w, 3), np.float32)
    for sigma in (1.5, 4.0, 10.0):
        noise = rng.normal(size=(h, w, 3)).astype(np.float32)
        img += cv2.GaussianBlur(noise, (0, 0), sigma) * sigma
    img = (img - img.min()) / (img.max() - img.min())
    return (255 * img).astype(np.uint8)


def shifted_pair(h: int, w: int, dx: float, dy: float) -> tuple[np.ndarray, np.ndarray]:
    """frame1 is frame0's content moved by (dx, dy): true flow (dx, dy) everywhere inside."""
    big = texture(h + 40, w + 40)
    frame0 = big[20 : 20 + h, 20 : 20 + w]
    M = np.float32([[1, 0, dx], [0, 1, dy]])
    frame1 = cv2.warpAffine(big, M, (w + 40, h + 40), flags=cv2.INTER_CUBIC)[
        20 : 20 + h, 20 : 20 + w
    ]
    return frame0, frame1


@pytest.fixture(scope="session")
def raft_weights(shared) -> Path:
    return shared / "raft" / "raft-small.pth"
