"""Axis letters: which sensor axis each camera axis is, written as three letters.

``YXz`` says camera x is the IMU's +Y, camera y its +X, and camera z its -Z: a
lower-case letter means the negative axis. As a matrix R (ω_cam = R ω_imu), row i has
±1 in the column of letter i. Gyroflow's ``.gcsv`` ``orientation`` uses the same letters
for which sensor axis each logged column is, which is the transpose.
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray

from stabilize.gyro.log import GyroError


def axes_matrix(code: str, *, what: str = "axes", proper: bool = True) -> NDArray[np.float64]:
    """R with row i = ±e(letter i): 'YXz' → [[0,1,0],[1,0,0],[0,0,-1]].

    A code that is not a permutation of XYZ, or (``proper``) whose matrix is a
    reflection, raises :class:`GyroError` naming ``what``.
    """
    if len(code) != 3 or sorted(code.upper()) != ["X", "Y", "Z"]:
        raise GyroError(
            f"{what} must be three letters naming the IMU axis of camera x, y, z, got {code!r}"
        )
    R = np.zeros((3, 3))
    for row, letter in enumerate(code):
        R[row, "XYZ".index(letter.upper())] = 1.0 if letter.isupper() else -1.0
    if proper and np.linalg.det(R) < 0:
        raise GyroError(f"{what} {code} is a reflection, not a rotation")
    return R


def axes_code(R: NDArray) -> str:
    """The nearest signed axis permutation as letters: the IMU axis of camera x, y, z."""
    out = ""
    for row in np.asarray(R):
        k = int(np.argmax(np.abs(row)))
        out += "XYZ"[k] if row[k] > 0 else "xyz"[k]
    return out


def signed_permutations() -> list[NDArray[np.float64]]:
    """The 24 rotations that map axes onto signed axes."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            M = np.zeros((3, 3))
            M[range(3), perm] = signs
            if np.linalg.det(M) > 0:
                out.append(M)
    return out
