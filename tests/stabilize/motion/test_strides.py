"""High frame rates: the pairs' turns held to the turn measured a stride of frames apart."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

import stabilize.motion.focal as focal_module
from rotation import so3
from stabilize import Settings
from stabilize.motion.focal import estimate_motion
from stabilize.motion.strides import MAX_MISS_DEG, chain, held_to_strides, stride_for, usable
from stabilize.motion.track import VisualTrack
from stabilize.pipeline import _motion, prepare
from stabilize.progress import no_progress
from stabilize.video import probe

EVERY = 8


def test_a_stride_spans_a_thirtieth_of_a_second():
    assert [stride_for(fps) for fps in (20, 29.97, 30, 44, 60, 120, 240, 0)] == [
        1, 1, 1, 1, 2, 4, 8, 1,
    ]  # fmt: skip


def _walk(seed: int = 0, strides: int = 3):
    """(track, strided, truth): pairs at 240 fps that all err alike (a walk's parallax
    leans every pair the same way), and their strides' exact turns and similarities."""
    rng = np.random.default_rng(seed)
    n = strides * EVERY
    truth = so3.exp_so3(np.radians(rng.normal(0, 0.1, (n, 3))))
    lean = so3.exp_so3(np.radians([[0.006, -0.004, 0.002]]))[0]
    measured = lean @ truth
    drift = np.array([2e-4, 0.0, 0.0, -1e-4])
    residual = rng.normal(0, 1e-4, (n, 4)) + drift  # a walk's drift, and noise
    times = np.arange(n + 1) / 240.0
    track = replace(
        VisualTrack.from_rotations(times, measured),
        residual=residual,
        likeness=np.ones(n),
        every=EVERY,
    )
    S = np.stack([chain(truth[j * EVERY : (j + 1) * EVERY]) for j in range(strides)])
    strided = replace(
        VisualTrack.from_rotations(times[::EVERY], S),
        residual=np.tile(EVERY * drift, (strides, 1)),
    )
    return track, strided, truth


def test_each_stride_s_pairs_compose_to_its_turn_and_err_less():
    track, strided, truth = _walk()
    held = held_to_strides(track, strided)
    for j in range(3):
        part = slice(j * EVERY, (j + 1) * EVERY)
        miss = chain(held.rotations[part]) @ strided.rotations[j].T - np.eye(3)
        assert np.abs(miss).max() < 1e-7  # rad: held within 1e-5°, the logarithm's own
        assert held.residual[part].sum(axis=0) == pytest.approx(strided.residual[j], abs=1e-12)
    before = np.degrees(so3.angle(track.rotations @ np.swapaxes(truth, -1, -2)))
    after = np.degrees(so3.angle(held.rotations @ np.swapaxes(truth, -1, -2)))
    assert after.mean() < 0.2 * before.mean()
    assert held.held is not None and np.allclose(held.residual, track.residual + held.held)


def test_a_stride_that_cannot_speak_for_its_pairs_leaves_them_as_voted():
    track, strided, _ = _walk()
    support = np.ones(len(track.rotations))
    support[3] = 0.01  # a subject won pair 3's vote: stride 0 is not used
    likeness = np.ones(len(track.rotations))
    likeness[12] = 0.5  # a cut, or a black frame, in stride 1
    track = replace(track, support=support, likeness=likeness)
    assert usable(track, strided).tolist() == [False, False, True]
    lost = replace(strided, support=np.array([1.0, 1.0, 0.01]))  # stride 2's vote lost
    assert usable(replace(track, support=np.ones(24), likeness=np.ones(24)), lost).tolist() == [
        True, True, False,
    ]  # fmt: skip
    far = np.radians(2 * MAX_MISS_DEG)
    wrong = replace(strided, rotations=so3.exp_so3(np.array([[far, 0, 0]] * 3)))
    assert not usable(replace(track, support=np.ones(24), likeness=np.ones(24)), wrong).any()
    held = held_to_strides(track, strided)
    assert np.array_equal(held.rotations[:16], track.rotations[:16])
    assert not np.array_equal(held.rotations[16:], track.rotations[16:])


def _truth(clip: Path) -> tuple[NDArray, float]:
    """The clip's true pair turns (N-1, 3, 3) and focal length, px."""
    rows = np.genfromtxt(clip.parent / "truth.csv", delimiter=",", names=True)
    quats = np.c_[rows["qx"], rows["qy"], rows["qz"], rows["qw"]]
    O = Rotation.from_quat(quats).as_matrix()
    return O[1:] @ np.swapaxes(O[:-1], -1, -2), float(rows["f"][0])


def _per_thirtieth(R, truth) -> float:
    """How far the turn of every 8 consecutive pairs lies from the truth's, deg (mean)."""
    spans = [slice(t, t + EVERY) for t in range(len(R) - EVERY)]
    misses = np.stack([chain(R[s]) @ chain(truth[s]).T for s in spans])
    return float(np.degrees(so3.angle(misses)).mean())


def test_a_240_fps_clip_is_estimated_on_its_strides(fast_walk, monkeypatch):
    truth, focal = _truth(fast_walk)
    info = probe(fast_walk)
    track, choice = estimate_motion(fast_walk, info, Settings())
    assert track.every == EVERY and len(track.strides.u) == (len(track.times) - 1) // EVERY
    # on its pairs alone f read 7% long: a pair turns too little to show its x²/f terms
    assert choice.source == "estimated" and abs(choice.px / focal - 1) < 0.03
    held, _ = estimate_motion(fast_walk, info, Settings(focal=focal))
    monkeypatch.setattr(focal_module, "stride_for", lambda fps: 1)
    alone, _ = estimate_motion(fast_walk, info, Settings(focal=focal))
    assert alone.every == 1 and alone.strides is None
    # a thirtieth of a second's turn: 0.078° off the truth on the pairs alone, 0.037 held
    assert _per_thirtieth(held.rotations, truth) < 0.6 * _per_thirtieth(alone.rotations, truth)


def test_under_a_rolling_shutter_the_similarities_stay_held_to_the_strides(fast_walk, tmp_path):
    # Dating a rolling shutter's rows measures each pair's similarity anew, from its own
    # vectors alone: at 240 fps their zoom added up to 0.0042 a stride off the stride's
    # own, and the output's zoom shook 1.2 px a thirtieth of a second where held 0.38
    settings = Settings(rolling_shutter=2.0)
    job = prepare(fast_walk, tmp_path / "out.mp4", settings, False)
    track, _, turns = _motion(fast_walk, job, settings, lambda *a: no_progress, lambda m: None)
    count = len(track.strides.u)
    per_stride = turns.residual[: count * EVERY].reshape(count, EVERY, 4).sum(axis=1)
    held = track.residual[: count * EVERY].reshape(count, EVERY, 4).sum(axis=1)
    assert np.abs(per_stride - held)[:, 2].mean() < 5e-4


def test_a_long_240_fps_clip_settles_its_focal_length_on_the_strides_so_far(fast_walk, monkeypatch):
    # as a 30 fps clip settles on its first MAX_PAIRS pairs, a 240 fps one settles on its
    # first MAX_PAIRS strides (4 s), so that the rest is voted once: "long" here once 32
    # strides (256 pairs of its 359) are measured
    searched = []
    search = focal_module.focal_from_track

    def spy(track, estimator, long_side):
        searched.append(len(track.rotations))
        return search(track, estimator, long_side)

    monkeypatch.setattr(focal_module, "MAX_PAIRS", 32)
    monkeypatch.setattr(focal_module, "focal_from_track", spy)
    _, focal = _truth(fast_walk)
    track, choice = estimate_motion(fast_walk, probe(fast_walk), Settings())
    assert searched[0] == 32  # the strides so far, not the pairs (256)
    assert choice.source == "estimated" and abs(choice.px / focal - 1) < 0.03
    assert track.samples is None and track.every == EVERY
