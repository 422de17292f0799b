"""Rolling-shutter correction: per-row turns from the gyro, and the row-by-row warp."""

import cv2
import numpy as np

from rotation import so3
from rotation.camera import intrinsics
from stabilize.gyro import GyroLog
from stabilize.gyro.integrate import attitude
from stabilize.gyro.rolling_shutter import frame_rotations, row_turns
from stabilize.warp.frames import warp_frame
from stabilize.warp.homography import homography
from tests.stabilize.helpers import covers, warp_frame_rolling

H, W = 240, 320
K = intrinsics(300.0, (H, W))
W_CAM = np.array([0.4, -0.9, 0.3])  # rad/s, constant
READOUT = 0.03


def constant_rate_attitude():
    t = np.linspace(0.0, 2.0, 801)
    return attitude(GyroLog(t, np.tile(W_CAM, (len(t), 1)), "const"))


def test_row_turns_are_the_rotation_between_row_times():
    att = constant_rate_attitude()
    times = np.array([0.5, 0.6])
    rs = row_turns(att, times, offset=0.1, readout=READOUT, height=H)
    assert rs.turns.shape == (2, len(rs.rows), 3, 3)
    # Row y is captured (y + ½)/H · readout after the first row; the middle row at ½ readout.
    dt = READOUT * ((rs.rows + 0.5) / H - 0.5)
    np.testing.assert_allclose(rs.turns[1], so3.exp_so3(-W_CAM * dt[:, None]), atol=1e-12)
    R = frame_rotations(att, times, 0.1, READOUT)
    np.testing.assert_allclose(R[0], so3.exp_so3(-W_CAM * 0.1), atol=1e-12)


def texture() -> np.ndarray:
    rng = np.random.default_rng(0)
    img = cv2.resize(rng.integers(0, 255, (H // 8, W // 8, 3), np.uint8), (W, H))
    return cv2.GaussianBlur(img, (0, 0), 1.5)


def rolling_capture(sharp: np.ndarray, turns: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """What a rolling-shutter camera records of the scene the middle row's camera sees
    as ``sharp``: pixel p on row y shows the ray K D(y)ᵀ K⁻¹ p of it."""
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float64)
    p = np.stack([xs, ys, np.ones_like(xs)], -1)
    k = np.clip(np.searchsorted(rows, ys) - 1, 0, len(rows) - 2)
    frac = ((ys - rows[k]) / (rows[k + 1] - rows[k]))[..., None, None]
    D = turns[k] + frac * (turns[k + 1] - turns[k])
    src = np.einsum("ij,hwjk,kl,hwl->hwi", K, np.swapaxes(D, -1, -2), np.linalg.inv(K), p)
    maps = (src[..., :2] / src[..., 2:]).astype(np.float32)
    return cv2.remap(sharp, maps[..., 0], maps[..., 1], cv2.INTER_LINEAR)


def test_the_row_by_row_warp_undoes_the_rolling_shutter():
    att = constant_rate_attitude()
    rs = row_turns(att, np.array([0.5]), 0.0, READOUT, H)
    sharp = texture()
    skewed = rolling_capture(sharp, rs.turns[0], rs.rows)
    C = np.swapaxes(rs.turns[0], -1, -2)  # no smoothing: only the per-row turn is undone
    H_rows = np.array([homography(K, c) for c in C])
    fixed = warp_frame_rolling(skewed, H_rows, rs.rows)
    inner = (slice(30, -30), slice(30, -30))
    err_fixed = np.abs(fixed[inner].astype(float) - sharp[inner]).mean()
    err_skewed = np.abs(skewed[inner].astype(float) - sharp[inner]).mean()
    assert err_fixed < 1.0 < 4.0 < err_skewed


def test_one_homography_for_every_row_is_the_plain_warp():
    frame = texture()
    Hm = homography(K, so3.exp_so3([0.01, -0.02, 0.005]), 1.1)
    rows = np.linspace(-0.5, H - 0.5, 5)
    same = warp_frame_rolling(frame, np.repeat(Hm[None], 5, 0), rows)
    diff = np.abs(same.astype(int) - warp_frame(frame, Hm))
    assert diff.mean() < 0.3 and diff.max() <= 6  # OpenCV's two samplers round differently


def test_coverage_accounts_for_the_row_turns():
    # A roll that differs from the top to the bottom row needs more zoom than either end.
    turns = so3.exp_so3(np.outer(np.linspace(-1, 1, 9), [0.0, 0.0, 0.03]))
    rows = np.linspace(-0.5, H - 0.5, 9)
    assert covers(K, np.eye(3), 1.0, (H, W))
    assert not covers(K, turns, 1.0, (H, W), rows)
    assert covers(K, turns, 1.2, (H, W), rows)
