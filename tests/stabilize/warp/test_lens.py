"""Lens profiles and the fisheye model: projection, the one-remap warp, and a fisheye clip
stabilised end to end with --lens."""

import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from typer.testing import CliRunner

from rotation import so3
from rotation.camera import intrinsics
from stabilize import Settings, estimate_rotations, stabilize_video
from stabilize.cli import app
from stabilize.motion.files import read_rotations
from stabilize.pipeline import prepare
from stabilize.video import FrameWriter, probe, read_frames
from stabilize.warp.frames import warp_frame
from stabilize.warp.homography import homography
from stabilize.warp.lens import Lens, LensError, pinhole_map, project, read_lens_profile, unproject
from tests.stabilize.helpers import SAMPLE, covers, held_upright, warp_frame_lens

COEFFS = [0.03, -0.01, 0.004, -0.001]


def profile(path: Path, size=(1280, 720), readout=None, **extra) -> Path:
    w, h = size
    data = {
        "calib_dimension": {"w": w, "h": h},
        "fisheye_params": {
            "camera_matrix": [[900.0, 0, (w - 1) / 2], [0, 900.0, (h - 1) / 2], [0, 0, 1]],
            "distortion_coeffs": COEFFS,
        },
        **({"frame_readout_time": readout} if readout else {}),
        **extra,
    }
    path.write_text(json.dumps(data))
    return path


def test_profile_is_scaled_to_the_video(tmp_path):
    lens = read_lens_profile(profile(tmp_path / "p.json", readout=8.5), (360, 640))
    assert lens.K[0, 0] == pytest.approx(450.0) and lens.K[0, 2] == pytest.approx(319.5)
    assert lens.readout_s == pytest.approx(0.0085)
    np.testing.assert_allclose(lens.coeffs, COEFFS)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (None, "no such lens profile"),
        ("{not json", "not a Gyroflow lens profile"),
        ('{"calib_dimension": {"w": 4, "h": 3}}', "missing or malformed"),
    ],
)
def test_bad_profiles(tmp_path, text, message):
    path = tmp_path / "p.json"
    if text is not None:
        path.write_text(text)
    with pytest.raises(LensError, match=message):
        read_lens_profile(path, (360, 640))


def test_a_profile_for_another_aspect_ratio_is_refused(tmp_path):
    with pytest.raises(LensError, match="aspect ratio"):
        read_lens_profile(profile(tmp_path / "p.json", size=(1440, 1080)), (360, 640))
    with pytest.raises(LensError, match="not supported"):
        read_lens_profile(profile(tmp_path / "q.json", distortion_model="poly5"), (720, 1280))


def lens_640() -> Lens:
    return Lens(intrinsics(420.0, (360, 640)), np.array(COEFFS))


def test_unproject_inverts_project_beyond_90_degrees():
    lens = lens_640()
    rng = np.random.default_rng(0)
    theta = rng.uniform(0, np.radians(100), 200)
    phi = rng.uniform(-np.pi, np.pi, 200)
    rays = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], -1)
    np.testing.assert_allclose(unproject(lens, project(lens, rays)), rays, atol=1e-9)


def fisheye_view(world: np.ndarray, K_world: np.ndarray, lens: Lens, A: np.ndarray, size):
    """What the fisheye camera turned by A (rays_world = Aᵀ rays_cam) sees of a wide
    pinhole image ``world``."""
    h, w = size
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    rays = unproject(lens, np.c_[xs.ravel(), ys.ravel()]) @ A
    p = rays @ K_world.T
    src = (p[:, :2] / p[:, 2:]).reshape(h, w, 2).astype(np.float32)
    return cv2.remap(world, src[..., 0], src[..., 1], cv2.INTER_LINEAR)


def test_the_lens_warp_turns_one_fisheye_view_into_another():
    lens, size = lens_640(), (360, 640)
    rng = np.random.default_rng(1)
    world = cv2.resize(rng.integers(0, 255, (150, 250, 3), np.uint8), (2000, 1200))
    world = cv2.GaussianBlur(world, (0, 0), 2.0)
    K_world = intrinsics(600.0, (1200, 2000))
    R = so3.exp_so3([0.02, -0.05, 0.03])  # camera 2 = R · camera 1 (CONVENTIONS.md)
    first = fisheye_view(world, K_world, lens, np.eye(3), size)
    second = fisheye_view(world, K_world, lens, R, size)
    # The correction turns the second camera back onto the first: C = Rᵀ.
    fixed = warp_frame_lens(second, lens, R.T, 1.0)
    flat = warp_frame(second, homography(lens.K, R.T))
    inner = (slice(20, -20), slice(20, -20))
    err_lens = np.abs(fixed[inner].astype(float) - first[inner]).mean()
    err_flat = np.abs(flat[inner].astype(float) - first[inner]).mean()
    assert err_lens < 1.5 and err_flat > 3 * err_lens


@pytest.fixture(scope="module")
def fisheye_clip(tmp_path_factory) -> tuple[Path, Path]:
    """The rendered sample seen through a fisheye lens (f 560 px at 640×360)."""
    folder = tmp_path_factory.mktemp("fisheye")
    info = probe(SAMPLE / "clip.mp4")
    meta = json.loads((SAMPLE / "truth.json").read_text())
    K_pin = np.array(meta["K"])
    lens = Lens(intrinsics(560.0, info.size), np.array(COEFFS))
    maps = pinhole_map(lens, info.size, 560.0, (K_pin[0, 2], K_pin[1, 2]))  # for its shape
    h, w = info.size
    ys, xs = np.mgrid[0:h, 0:w].astype(np.float64)
    p = unproject(lens, np.c_[xs.ravel(), ys.ravel()]) @ K_pin.T
    src = (p[:, :2] / p[:, 2:]).reshape(h, w, 2).astype(np.float32)
    assert maps[0].shape == (h, w)
    clip = folder / "fisheye.mp4"
    with FrameWriter(clip, info.size, info.fps) as writer:
        for frame in read_frames(SAMPLE / "clip.mp4", info=info):
            writer.write(cv2.remap(frame, src[..., 0], src[..., 1], cv2.INTER_LINEAR))
    data = {
        "calib_dimension": {"w": w, "h": h},
        "fisheye_params": {"camera_matrix": lens.K.tolist(), "distortion_coeffs": COEFFS},
    }
    (folder / "lens.json").write_text(json.dumps(data))
    return clip, folder / "lens.json"


def test_fisheye_rotations_are_estimated_through_the_lens(fisheye_clip):
    clip, lens_path = fisheye_clip
    info = probe(clip)
    truth = read_rotations(SAMPLE / "truth.csv")
    R_true = so3.exp_so3(np.array([truth[k] for k in range(89)]))
    lens = read_lens_profile(lens_path, info.size)
    through = estimate_rotations(clip, info, Settings(), lens=lens)
    as_pinhole = estimate_rotations(clip, info, Settings(focal=560.0))
    err_lens = so3.angular_error_deg(through.rotations, R_true).mean()
    err_pinhole = so3.angular_error_deg(as_pinhole.rotations, R_true).mean()
    # As accurate as on the pinhole original (0.035°); the lens ignored costs 0.015° more.
    assert err_lens < 0.045 and err_pinhole > err_lens + 0.01


def test_the_rotations_command_reads_the_flow_through_the_lens(fisheye_clip, tmp_path):
    # rotations had no --lens: a fisheye clip's rotations were a pinhole's
    clip, lens_path = fisheye_clip
    out = tmp_path / "rot.csv"
    args = ["rotations", str(clip), "-o", str(out), "-q", "--lens", str(lens_path)]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "focal length 560.0 px" in result.output and "lens)" in result.output
    truth = read_rotations(SAMPLE / "truth.csv")
    found = read_rotations(out)
    R_true = so3.exp_so3(np.array([truth[k] for k in range(89)]))
    R = so3.exp_so3(np.array([found[k] for k in range(89)]))
    assert so3.angular_error_deg(R, R_true).mean() < 0.045


@pytest.mark.parametrize("command", ["run", "rotations", "compare", "batch"])
def test_a_lens_with_a_focal_length_too_is_refused(tmp_path, command):
    # run estimated at --fov's focal length while it warped at the profile's
    lens = profile(tmp_path / "lens.json")
    out = str(tmp_path / "out")
    args = {
        "run": [str(SAMPLE / "clip.mp4"), out + ".mp4"],
        "rotations": [str(SAMPLE / "clip.mp4"), "-o", out + ".csv"],
        "compare": [str(SAMPLE / "clip.mp4"), "--gyro", str(SAMPLE / "gyro.csv")],
        "batch": [str(SAMPLE), out],
    }[command]
    for focal in (["--fov", "60"], ["--focal", "500"]):
        result = CliRunner().invoke(app, [command, *args, "--lens", str(lens), *focal])
        assert result.exit_code == 2
        assert "error: --lens brings its own focal length" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lens.json"]


def test_stabilising_a_fisheye_clip_with_its_lens_profile(fisheye_clip, tmp_path):
    clip, lens_path = fisheye_clip
    out = tmp_path / "steady.mp4"
    summary, planned = stabilize_video(clip, out, Settings(lens=str(lens_path)))
    assert summary["frames"] == 90 and out.is_file()
    assert planned.lens is not None and 1.0 < summary["zoom"] <= 1.15 + 1e-6
    # The zoom is found through the lens: every frame's border stays inside the input.
    size = probe(clip).size
    for C, zoom in zip(planned.corrections(), planned.zoom, strict=True):
        assert covers(planned.K, C, zoom, size, lens=planned.lens)
    means = [frame.mean() for frame in read_frames(out)]
    assert len(means) == 90 and min(means) > 20  # warped content, not black


@pytest.mark.parametrize("rotation", [90, 270])
def test_a_profile_applies_to_a_clip_held_upright_as_stored(tmp_path, rotation):
    # calibrated on the frames as the sensor stores them, which the clip is warped in
    path = tmp_path / "p.json"
    matrix = [[900.0, 0, 700.0], [0, 880.0, 300.0], [0, 0, 1]]
    fisheye = {"camera_matrix": matrix, "distortion_coeffs": COEFFS}
    path.write_text(
        json.dumps({"calib_dimension": {"w": 1280, "h": 720}, "fisheye_params": fisheye})
    )
    tagged = held_upright(SAMPLE / "clip.mp4", tmp_path, rotation)
    job = prepare(tagged, tmp_path / "out.mp4", Settings(lens=str(path)), overwrite=False)
    np.testing.assert_array_equal(job.lens.K, read_lens_profile(path, (360, 640)).K)
    assert job.info.size == (360, 640) and job.info.shown_size == (640, 360)
