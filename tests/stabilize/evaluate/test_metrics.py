import cv2
import numpy as np
import pytest

from stabilize.evaluate.metrics import (
    ClipMetrics,
    ShakeSpread,
    evaluate,
    evaluate_against,
    evaluate_pair,
    low_frequency_share,
    scale_and_distortion,
    shake_spread,
)
from stabilize.synth import SynthOptions, render_frames

SMALL = {"size": (180, 320), "seconds": 3.0, "fps": 30.0, "crowd": 0, "seed": 3, "walk": 0}


@pytest.fixture(scope="module")
def shaken() -> list[np.ndarray]:
    return [f for f, _ in render_frames(SynthOptions(shake_deg=2.0, **SMALL))]


@pytest.fixture(scope="module")
def panning() -> list[np.ndarray]:
    return [f for f, _ in render_frames(SynthOptions(shake_deg=0.0, **SMALL))]


@pytest.fixture(scope="module")
def read(shaken, panning) -> dict[str, ClipMetrics]:
    """The metrics of the clip held still, the smooth pan and the shaken street, read once
    for the tests here (each reading costs about a second)."""
    still = evaluate([shaken[0]] * len(shaken))
    return {"still": still, "smooth": evaluate(panning), "shaky": evaluate(shaken)}


@pytest.fixture(scope="module")
def jittered(shaken) -> list[np.ndarray]:
    """Frames shifted by 0, 2, 0, 2, ... px and cropped to 304 px: every frame-to-frame
    motion is ±2 px, which the low-pass (0.5 s) averages to about 0, so all of it is
    shake: 2 px RMS."""
    return [np.roll(shaken[0], 2 * (k % 2), axis=1)[:, 8:-8] for k in range(60)]


@pytest.fixture(scope="module")
def jitter_read(jittered) -> ClipMetrics:
    return evaluate(jittered)


@pytest.fixture(scope="module")
def jitter_spread(jittered, jitter_read) -> ShakeSpread:
    """The jitter's residual shake read as it is and mirrored three ways."""
    return shake_spread(jittered, jitter_read.residual_shake_px)


def test_a_steady_clip_ranks_above_a_shaken_one(read):
    still, smooth, shaky = read["still"], read["smooth"], read["shaky"]
    assert still.stability == 1.0 and still.itf_db == 100.0
    assert smooth.stability > shaky.stability + 0.1
    assert smooth.itf_db > shaky.itf_db + 3


def test_the_residual_shake_ranks_a_steady_clip_above_a_shaken_one(read):
    still, smooth, shaky = read["still"], read["smooth"], read["shaky"]
    assert still.residual_shake_px < 0.05  # registration noise only
    assert smooth.residual_shake_px < 0.25 * shaky.residual_shake_px
    assert shaky.residual_shake_px > 1.0 and shaky.residual_shake_deg > 0.01


def test_the_residual_shake_is_in_pixels_of_the_motion(jitter_read):
    assert jitter_read.residual_shake_px == pytest.approx(2.0, rel=0.1)


def test_the_spread_reads_the_same_motion_mirrored(shaken, jitter_read, jitter_spread, read):
    # The 2 px jitter: mirrored left-right, upside down or both it is still ±2 px from
    # frame to frame, so every reading is 2 px; the features are other ones.
    spread = jitter_spread
    assert spread.readings[0] == jitter_read.residual_shake_px
    assert len(spread.readings) == 4
    assert spread.readings == pytest.approx([2.0] * 4, rel=0.1)
    # On the shaken street the readings agree within the metric's noise, yet are other
    # registrations (not the same frames read four times)
    shaky = read["shaky"].residual_shake_px
    street = shake_spread(shaken, shaky)
    readings, figures = street.readings, street.as_dict()
    assert readings == pytest.approx([shaky] * 4, rel=0.1) and len(set(readings)) > 1
    assert figures["min"] <= figures["mean"] <= figures["max"]
    assert figures["mean"] == pytest.approx(np.mean(readings))


def test_the_spread_reads_at_other_registration_sizes_too(shaken, jittered, jitter_spread, read):
    # The 2 px jitter (frames 304 px wide), registered at 288 px as it is and mirrored three
    # ways, and at its own size mirrored: 2 px each time
    as_it_is = jitter_spread.readings[0]
    finer = shake_spread(jittered, as_it_is, sizes=(288, 640)).readings
    assert len(finer) == 8 and finer[0] == as_it_is
    assert finer == pytest.approx([2.0] * 8, rel=0.1)
    assert finer[5:] == jitter_spread.readings[1:]
    # On the shaken street, other registrations than the frames' own size's
    street = shake_spread(shaken, read["shaky"].residual_shake_px, sizes=(288,)).readings
    assert len(street) == 5 and len(set(street)) == 5


def test_a_zoomed_crop_ranks_below_an_uncropped_one(shaken):
    def zoom(frame: np.ndarray, z: float) -> np.ndarray:
        h, w = frame.shape[:2]
        M = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), 0.0, z)
        return cv2.warpAffine(frame, M, (w, h), flags=cv2.INTER_LINEAR)

    shaken = shaken[:45]  # the crop is read frame by frame: 1.5 s says what 3 s did
    _, same = evaluate_pair(shaken, shaken)
    _, cropped = evaluate_pair(shaken, [zoom(f, 1.25) for f in shaken])
    assert same.cropping_ratio == pytest.approx(1.0, abs=0.01)
    assert cropped.cropping_ratio == pytest.approx(0.8, abs=0.02)
    assert cropped.distortion > 0.97


def test_several_outputs_read_against_one_original_as_each_alone(shaken):
    # the benches read two tools' outputs in one pass over the original
    shaken = shaken[:40]  # a second and a third: the 0.5 s high-pass twice over
    steadier = [shaken[0]] * len(shaken)
    zoomed = [f[8:-8, 16:-16] for f in shaken]
    zoomed = [cv2.resize(f, (shaken[0].shape[1], shaken[0].shape[0])) for f in zoomed]
    before, (a, b) = evaluate_against(shaken, [steadier, zoomed])
    alone_a, alone_b = evaluate_pair(shaken, steadier)[1], evaluate_pair(shaken, zoomed)[1]
    assert before.residual_shake_px == evaluate(shaken).residual_shake_px  # (the first 40)
    for m, alone in ((a, alone_a), (b, alone_b)):
        assert m.residual_shake_px == alone.residual_shake_px
        assert (m.cropping_ratio, m.distortion) == (alone.cropping_ratio, alone.distortion)
    assert a.residual_shake_px < 0.1 < b.residual_shake_px and b.cropping_ratio < 0.95


def test_metric_building_blocks():
    assert scale_and_distortion(np.diag([2.0, 0.5, 1.0])) == (1.0, 0.25)
    t = np.arange(64)
    assert low_frequency_share(np.sin(2 * np.pi * 2 * t / 64)) > 0.99
    assert low_frequency_share(np.sin(2 * np.pi * 20 * t / 64)) < 0.01


def test_progress_is_told_of_every_pair_of_frames(shaken):
    told: list[int] = []
    evaluate_pair(shaken[:6], shaken[:5], progress=told.append)  # the shorter clip decides
    assert told == [1] * 5


def test_clips_of_other_frames_are_refused_not_paired_in_step(shaken):
    # a GIF of a 60 fps clip holds every other frame: its figures were of frames paired
    # with the original's shot at other times
    with pytest.raises(ValueError, match=r"different frames \(12 in the original, 6 in the st"):
        evaluate_pair(shaken[:12], shaken[:12:2])


def test_registration_survives_featureless_frames():
    blank = [np.full((90, 160, 3), 128, np.uint8)] * 10
    _, m = evaluate_pair(blank, blank)
    assert m.cropping_ratio == 1.0 and m.registration_failures > 0


def test_a_thin_strip_of_texture_registers_as_failures_not_as_distortion():
    # Only a band 8 px high carries features: no homography is pinned down across it, and
    # a fit through it would read as any stretch (cockatoo's feathers: 0.11)
    rng = np.random.default_rng(4)
    frames = []
    for k in range(8):
        frame = np.full((180, 320, 3), 128, np.uint8)
        frame[86:94] = rng.integers(0, 256, (8, 320, 1), dtype=np.uint8)
        frames.append(np.roll(frame, k, axis=1))
    _, m = evaluate_pair(frames, frames)
    assert m.distortion == 1.0 and m.registration_failures >= len(frames)
    assert m.residual_shake_px == pytest.approx(0.0, abs=0.05)  # a steady 1 px pan


def test_the_wobble_is_the_shear_between_frames_in_pixels(shaken, read):
    # Frames sheared by 0, s, 0, s, ...: x moves by s·(y - centre); each frame-to-frame
    # homography's non-similar part is then s/2 (half the shear is a rotation), so the
    # wobble is s/2 · w/2. A turning global-shutter camera (the shaken clip) scores about
    # 0, up to the registration's noise at this size.
    frame = shaken[0]
    h, w = frame.shape[:2]
    s = 0.02
    shear = np.array([[1.0, s, -s * (h - 1) / 2], [0.0, 1.0, 0.0]])
    sheared = cv2.warpAffine(frame, shear, (w, h), flags=cv2.INTER_LINEAR)
    jello = [(frame if k % 2 else sheared)[16:-16, 16:-16] for k in range(30)]
    assert evaluate(jello).wobble_px == pytest.approx(s / 2 * (w - 32) / 2, rel=0.15)
    assert read["shaky"].wobble_px < 0.25 * evaluate(jello).wobble_px  # noise at 320 px
