"""End to end on short rendered clips, through the public API: timing, audio, borders,
zoom, rotation metadata, bit depth."""

import json
import math
import os
import subprocess
from pathlib import Path

import av
import numpy as np
import pytest

from rotation import so3
from stabilize import Settings, stabilize_video
from stabilize.evaluate.metrics import evaluate_pair
from stabilize.gyro.log import GyroError
from stabilize.motion.focal import initial_focal
from stabilize.pipeline import prepare
from stabilize.synth import SynthOptions, trajectory
from stabilize.video import Encoding, ffmpeg_exe, frame_times, probe, read_frames
from tests.stabilize.conftest import render
from tests.stabilize.helpers import SAMPLE, boxed, combing, damaged, held_upright, squeezed, woven


@pytest.fixture(scope="module")
def stabilised(shaky, tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("out") / "steady.mp4"
    summary, planned = stabilize_video(shaky, out, Settings(fov=70.0))
    return out, summary, planned


def test_frames_timestamps_and_audio_are_kept(shaky, stabilised):
    out, summary, _ = stabilised
    a, b = probe(shaky), probe(out)
    assert b.size == a.size and b.has_audio and a.has_audio
    np.testing.assert_allclose(frame_times(out), frame_times(shaky), atol=1e-3)
    assert summary["frames"] == len(frame_times(shaky)) == 60


def test_variable_frame_rate_timestamps_are_kept(shaky, tmp_path):
    vfr = tmp_path / "vfr.mp4"
    jitter = ["-vf", "setpts=(N+0.4*mod(N\\,3))/30/TB", "-enc_time_base:v", "1:90000"]
    subprocess.run(
        [
            ffmpeg_exe(),
            "-v",
            "error",
            "-i",
            str(shaky),
            *jitter,
            "-fps_mode",
            "passthrough",
            "-c:a",
            "copy",
            str(vfr),
        ],
        check=True,
    )
    times = frame_times(vfr)
    assert len(times) == 60 and np.ptp(np.diff(times)) > 0.01  # really variable
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(vfr, out, Settings(fov=70.0))
    np.testing.assert_allclose(frame_times(out), times, atol=1e-3)
    assert summary["frames"] == 60 and probe(out).has_audio
    assert not list(tmp_path.glob("*.cfr.mp4"))  # the intermediate file is gone


def test_the_summary_gives_the_cropping_ratio_an_evaluation_reads(shaky, stabilised):
    # Not 1/zoom: the 2-D correction zooms out about its frames' middles (the real clips
    # keep 0.874-0.886 of their width at zoom 1.15), and the tools are compared at equal crop
    out, summary, _ = stabilised
    _, measured = evaluate_pair(read_frames(shaky), read_frames(out), 30.0)
    assert 1 / summary["zoom"] - 1e-9 <= summary["cropping_ratio"] < 1.0
    assert summary["cropping_ratio"] == pytest.approx(measured.cropping_ratio, abs=0.005)


def test_no_black_border_in_auto_crop(stabilised):
    out, _, _ = stabilised
    for frame in read_frames(out):
        edges = np.concatenate([frame[0], frame[-1], frame[:, 0], frame[:, -1]])
        assert np.mean(edges.max(axis=1) < 8) < 0.01  # no black pixels along the borders


def test_the_residual_jitter_is_a_fraction_of_the_input(shaky, stabilised):
    _, _, planned = stabilised
    opts = json.loads((shaky.parent / "truth.json").read_text())
    motion = SynthOptions(
        seed=opts["seed"],
        seconds=opts["seconds"],
        shake_deg=opts["shake_deg"],
        size=tuple(opts["size"]),
    ).motion
    O_true = trajectory.orientation(motion, planned.times)
    C = planned.smooth @ np.swapaxes(planned.raw, -1, -2)  # the turn (no 2-D part)
    out = C @ O_true  # the output camera's true orientation

    def jitter(O):
        return np.std(
            np.diff(np.degrees(so3.log_so3(O[1:] @ np.swapaxes(O[:-1], -1, -2))), 2, axis=0)
        )

    assert jitter(out) < 0.25 * jitter(O_true)


def test_zoom_limit_is_respected_and_dynamic_crop_has_no_border(shaky, tmp_path):
    out = tmp_path / "dyn.mp4"
    summary, planned = stabilize_video(
        shaky, out, Settings(fov=70.0, crop="dynamic", max_zoom=1.08)
    )
    assert planned.zoom.max() <= 1.08 + 1e-6
    assert summary["zoom"] <= 1.08 + 1e-6
    for frame in read_frames(out):
        edges = np.concatenate([frame[0], frame[-1], frame[:, 0], frame[:, -1]])
        assert np.mean(edges.max(axis=1) < 8) < 0.01


def test_a_path_bent_within_the_budget_is_said(shaky, tmp_path, monkeypatch):
    # As when the steadiest-path programme finds no answer (violent shake at a wrong f)
    monkeypatch.setattr("stabilize.path.plan.optimal_path", lambda *args, **kwargs: None)
    heard = []
    summary, planned = stabilize_video(
        shaky, tmp_path / "bent.mp4", Settings(fov=70.0, max_zoom=1.08), notify=heard.append
    )
    assert summary["path"] == planned.planner == "bent"
    assert any(notice.startswith("path: ") and "--max-zoom" in notice for notice in heard)
    assert planned.zoom.max() <= 1.08 + 1e-6


def test_a_static_clip_comes_out_unchanged(tmp_path):
    clip = render(tmp_path / "static", seed=1, shake_deg=0.0, pan_deg=0.0, walk=0.0, crowd=0)
    out = tmp_path / "out.mp4"
    summary, _planned = stabilize_video(clip, out, Settings(fov=70.0))
    assert summary["zoom"] < 1.01
    a = np.stack(list(read_frames(clip))).astype(float)
    b = np.stack(list(read_frames(out))).astype(float)
    assert np.abs(a - b).mean() < 2.5  # compression only


def test_portrait_rotation_metadata_is_honoured(shaky, tmp_path):
    rotated = held_upright(shaky, tmp_path)
    info = probe(rotated)
    assert info.rotation in (90, 270) and info.size == (320, 180)  # displayed upright
    # the default field of view spans the long side, however the phone was held
    upright, level = (
        initial_focal(Settings(), info, None),
        initial_focal(Settings(), probe(shaky), None),
    )
    assert upright.source == "default" and upright.px == pytest.approx(level.px)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(rotated, out, Settings(fov=50.0))
    result = probe(out)
    assert result.size == (320, 180) and result.rotation == 0
    assert summary["frames"] == 60
    # and so does a given one, the figure a maker quotes
    given = summary["focal"]
    assert given["px"] == pytest.approx(160 / math.tan(math.radians(25)))
    assert given["fov_deg"] == pytest.approx(50.0)


@pytest.mark.parametrize("rotation", [90, 180])
def test_a_turned_clip_is_stabilised_as_its_sensor_stored_it(shaky, tmp_path, rotation):
    # A phone held upright (90°) or upside down (180°). Its rows are the sensor's, read out
    # in order: decoded upright, a rendered 30 ms readout tagged upright read 3.1 ms along
    # the rows, and tagged upside down -6.7; as stored both read 28.9, as level
    level, upright = tmp_path / "level.mp4", tmp_path / "upright.mp4"
    settings = Settings(fov=50.0, preview=True)
    wanted, _ = stabilize_video(shaky, level, settings)
    got, _ = stabilize_video(held_upright(shaky, tmp_path, rotation), upright, settings)
    assert got["rolling_shutter"] == wanted["rolling_shutter"]
    assert got["rolling_shutter"]["source"] == "estimated"
    assert got["zoom"] == wanted["zoom"] and got["focal"] == wanted["focal"]
    # shown upright, the original beside the stabilised frame, with no display rotation
    assert got["display_rotation"] == rotation and wanted["display_rotation"] == 0
    assert probe(upright).rotation == 0 and got["size"] == (
        wanted["size"][::-1] if rotation == 90 else wanted["size"]
    )
    pairs = zip(read_frames(upright), read_frames(level), strict=True)
    for shown, frame in pairs:
        w = frame.shape[1] // 2
        halves = (np.rot90(frame[:, :w], rotation // 90), np.rot90(frame[:, w:], rotation // 90))
        expected = np.hstack(halves).astype(int)
        assert np.abs(shown.astype(int) - expected).mean() < 4  # the encoders' own loss


@pytest.mark.parametrize(
    ("name", "encode"),
    [
        ("ten.mp4", ["-c:v", "libx264", "-pix_fmt", "yuv420p10le"]),
        # a camera's or a grade's 4:2:2 at 12 bits: 4:2:0 video keeps 10 of them
        ("twelve.mkv", ["-c:v", "ffv1", "-pix_fmt", "yuv422p12le"]),
    ],
)
def test_a_deep_source_stays_10_bit(shaky, tmp_path, name, encode):
    ten = tmp_path / name
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), *encode, "-c:a", "copy"]
    subprocess.run([*cmd, str(ten)], check=True)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(ten, out, Settings(fov=70.0))
    assert probe(out).pix_fmt.startswith("yuv420p10") and summary["frames"] == 60
    frames = list(read_frames(out))
    assert len(frames) == 60 and min(f.mean() for f in frames) > 20  # content, not black
    # HEVC, which Apple's devices and browsers play at 10 bits, where H.264 plays in few
    written = probe(out)
    assert (written.codec, written.streams[0].tag) == ("hevc", "hvc1")
    assert summary["encoder"] == {"codec": "libx265", "pix_fmt": "yuv420p10le"}
    assert any(n.startswith("10-bit video: encoded with libx265") for n in summary["notices"])


def test_an_image_sequence_is_read_from_its_lowest_number_at_the_rate_given(shaky, tmp_path):
    # numbered from 99, as phone-cc9's frames are (FFmpeg alone tries only 0–4)
    pattern = tmp_path / "RE_frame-%d.jpg"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "20", "-q:v", "2"]
    subprocess.run([*cmd, "-start_number", "99", str(pattern)], check=True)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(pattern, out, Settings(fov=70.0, fps=24.0))
    assert summary["frames"] == 20 and probe(out).fps == 24.0
    assert np.allclose(np.diff(frame_times(out)), 1 / 24, atol=1e-3)
    # without --fps it is read at 30 fps, which is said (a 60 fps burst played at half speed)
    assert not any("holds no frame rate" in n for n in summary["notices"])
    unsaid = prepare(pattern, tmp_path / "o30.mp4", Settings(fov=70.0), False).notices
    assert "an image sequence holds no frame rate: read at 30 fps (--fps sets it)" in unsaid


def test_a_colon_in_a_relative_name_is_not_taken_for_a_protocol(shaky, tmp_path, monkeypatch):
    # an ISO time in a name, as cameras and recorders write it: FFmpeg read "take:" as a
    # protocol, and the clip was "not a video FFmpeg can read"
    monkeypatch.chdir(tmp_path)
    Path("take:10:11:12.mp4").write_bytes(shaky.read_bytes())
    summary, _ = stabilize_video("take:10:11:12.mp4", "out:1.mp4", Settings(fov=70.0))
    assert summary["frames"] == 60 and probe("out:1.mp4").has_audio


def test_a_deep_source_keeps_the_encoder_asked_for(shaky, tmp_path):
    ten = tmp_path / "ten.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-t", "1", "-c:v", "libx264"]
    subprocess.run([*cmd, "-pix_fmt", "yuv420p10le", str(ten)], check=True)
    out = tmp_path / "out.mkv"
    settings = Settings(fov=70.0, encoding=Encoding(codec="libx264", preset="ultrafast"))
    summary, _ = stabilize_video(ten, out, settings)
    assert (probe(out).codec, probe(out).pix_fmt) == ("h264", "yuv420p10le")
    assert not any(n.startswith("10-bit video") for n in summary["notices"])


def test_the_public_api_names_the_job_and_its_stages():
    import stabilize

    for name in stabilize.__all__:
        assert getattr(stabilize, name).__doc__, name
    with pytest.raises(AttributeError):
        stabilize.no_such_name  # noqa: B018


def test_the_summary_serialises_every_setting():
    import json
    from pathlib import Path

    from stabilize.pipeline import settings_summary

    settings = Settings(flow="raft", flow_options={"weights": Path("w.pth"), "device": "cpu"})
    text = json.dumps(settings_summary(settings))
    assert '"weights": "w.pth"' in text and '"codec": null' in text


def test_an_interlaced_clip_comes_out_progressive_every_frame_kept(tmp_path):
    scene = render(tmp_path / "scene", seed=3, shake_deg=1.5, fps=50.0)  # 2 s
    clip = woven(scene, tmp_path)  # 50 frames of 25i, top field first
    out = tmp_path / "steady.mp4"
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0))
    assert summary["field_order"] == "tff" and summary["deinterlaced"]
    assert any("deinterlaced" in n for n in summary["notices"])
    np.testing.assert_allclose(frame_times(out), frame_times(clip), atol=1e-3)
    assert summary["frames"] == 50 and probe(out).field_order == "progressive"
    # warped woven (--deinterlace off), the fields blend into combs: 0.72, against 0.29
    # deinterlaced first and 0.50 for the 50 fps scene's own frames
    assert np.median([combing(f) for f in read_frames(out)]) < 0.45


def test_each_field_becomes_a_frame_at_its_own_time(tmp_path):
    # --deinterlace fields: 25i back to the 50 fps scene it was woven from (50i → 50p)
    scene = render(tmp_path / "scene", seed=3, shake_deg=1.5, fps=50.0)  # 2 s
    clip = woven(scene, tmp_path)
    info = probe(clip).deinterlaced("fields")
    fields = [f.astype(int) for f in read_frames(clip, info=info)]
    frames = [f.astype(int) for f in read_frames(scene)]
    assert len(fields) == len(frames) == 100 and info.fps == 50
    # each is its own moment's frame: nearer it than the frame before or after it (by
    # 0.37 of the distance at the median, 0.85 at worst, where the shake paused)
    ratios = [
        np.abs(fields[k] - frames[k]).mean()
        / min(np.abs(fields[k] - frames[j]).mean() for j in (k - 1, k + 1))
        for k in range(1, 99)
    ]
    assert max(ratios) < 1 and np.median(ratios) < 0.5
    out = tmp_path / "steady.mp4"
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0, deinterlace="fields"))
    assert summary["frames"] == 100 and probe(out).fps == 50
    np.testing.assert_allclose(frame_times(out), frame_times(scene), atol=1e-3)
    assert any("25 → 50 frames a second" in n for n in summary["notices"])


def test_an_anamorphic_clip_comes_out_in_square_pixels_as_shown(tmp_path):
    clip = squeezed(tmp_path)  # 480×360 stored, 4:3 pixels: shown 640×360
    out = tmp_path / "steady.mp4"
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0))
    shown = probe(out)
    assert shown.size == (360, 640) and shown.pixel_aspect == "1:1"
    assert summary["pixel_aspect"] == "4:3" and summary["size"] == [640, 360]
    assert any("anamorphic" in n for n in summary["notices"])
    np.testing.assert_allclose(frame_times(out), frame_times(clip), atol=1e-3)


def _bar_edges(path: Path) -> np.ndarray:
    """Each frame's first row from the top whose middle is not black."""
    return np.array([np.argmax(f[:, 100:220].max(axis=(1, 2)) > 40) for f in read_frames(path)])


def test_black_bars_stay_still_around_the_stabilised_picture(shaky, tmp_path):
    clip = boxed(shaky, tmp_path, "320:240:0:30")  # a letterbox: 30 px above and below
    out = tmp_path / "steady.mp4"
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0))
    assert summary["bars"] == [30, 30, 0, 0] and summary["size"] == [320, 240]
    assert any("black bars" in n for n in summary["notices"])
    assert probe(out).size == (240, 320) and summary["frames"] == 60
    np.testing.assert_allclose(frame_times(out), frame_times(clip), atol=1e-3)
    np.testing.assert_array_equal(_bar_edges(out), 30)  # the picture starts at row 30
    # the picture's own edge, warped with the bars, wanders with the shake
    warped = tmp_path / "warped.mp4"
    stabilize_video(clip, warped, Settings(fov=70.0, bars="off"))
    assert np.ptp(_bar_edges(warped)) > 4


@pytest.mark.parametrize(("pix_fmt", "halved"), [("yuv422p", True), ("yuv420p", False)])
def test_colour_finer_than_the_output_writes_is_said(shaky, tmp_path, pix_fmt, halved):
    # a camera's or ProRes's 4:2:2 went to 4:2:0 silently
    clip = tmp_path / f"{pix_fmt}.mkv"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "10", "-an"]
    subprocess.run([*cmd, "-c:v", "libx264", "-pix_fmt", pix_fmt, str(clip)], check=True)
    summary, _ = stabilize_video(clip, tmp_path / "out.mp4", Settings(fov=70.0))
    said = [n for n in summary["notices"] if "colour" in n]
    assert said == ([f"the source's 4:2:2 colour ({pix_fmt}) is written as 4:2:0 (yuv420p), as "
                     "libx264 writes it here; ProRes, DNxHR (--codec prores_ks, dnxhd), PNG, "
                     "TIFF and --pix-fmt keep finer colour"] if halved else [])  # fmt: skip


def test_a_pixel_format_a_gif_cannot_take_is_said_to_have_no_effect(shaky, tmp_path):
    # a GIF's palette is its pixels: --pix-fmt was passed over silently
    settings = Settings(fov=70.0, encoding=Encoding(pix_fmt="yuv444p"))
    summary, _ = stabilize_video(shaky, tmp_path / "out.gif", settings)
    assert "--pix-fmt yuv444p has no effect on GIF: it writes pal8" in summary["notices"]


def test_a_damaged_clip_is_stabilised_from_the_frames_that_decode(shaky, tmp_path):
    # it was refused ("truncated or damaged: the container lists 49 frames, only 41 decode")
    ts, out = damaged(shaky, tmp_path), tmp_path / "out.mp4"
    decoded = frame_times(ts, decoded=True)
    assert len(decoded) < len(frame_times(ts)) - 1
    heard: list[str] = []
    summary, _ = stabilize_video(ts, out, Settings(fov=70.0), notify=heard.append)
    assert summary["frames"] == len(decoded) and probe(out).has_audio
    np.testing.assert_allclose(frame_times(out), decoded, atol=1e-3)  # each at its own time
    assert any(line.startswith("damaged: ") for line in heard)


def test_a_gyro_log_a_damaged_clip_cannot_match_is_refused_naming_the_damage(tmp_path):
    # the frames decoded after the gap turn as garbage: the refusal advised checking the
    # log, and giving its offset and axes, which fail the same check
    ts = damaged(SAMPLE / "clip.mp4", tmp_path)
    settings = Settings(fov=70.0, gyro=str(SAMPLE / "gyro.csv"))
    damage = r"the video is damaged: \d+ of its \d+ frames do not decode"
    with pytest.raises(GyroError, match=damage):
        stabilize_video(ts, tmp_path / "out.mp4", settings)


def test_a_clip_damaged_at_its_start_keeps_its_video_in_sync(shaky, tmp_path):
    # the first frame that decoded was written at the start, ahead of its audio (by
    # 0.17 s here, 2.7 s on a 12 s clip)
    ts, out = damaged(shaky, tmp_path, within=(0.0, 0.3)), tmp_path / "out.mkv"
    lead = frame_times(ts, decoded=True)[0]
    assert lead > 0.1  # five frames lost
    stabilize_video(ts, out, Settings(fov=70.0))

    def starts(path: Path) -> list[float]:
        with av.open(str(path)) as c:
            return [float(s.start_time * s.time_base) for s in c.streams]

    (video, audio), (source_video, source_audio) = starts(out), starts(ts)
    assert video - audio == pytest.approx(source_video - source_audio + lead, abs=0.002)


def test_a_name_that_is_not_utf8_works(shaky, tmp_path):
    # a Latin-1 name off an old camera's card or a zip archive: "'utf-8' codec can't encode
    # character '\udce9': surrogates not allowed", the input's in the decoder's command,
    # the output's in its temporary name
    clip = tmp_path / os.fsdecode(b"caf\xe9.mp4")
    clip.write_bytes(shaky.read_bytes())
    out = tmp_path / os.fsdecode(b"d\xe9") / os.fsdecode(b"steady \xe9t\xe9.mp4")
    summary, _ = stabilize_video(clip, out, Settings(fov=70.0))
    assert summary["frames"] == 60 and probe(out).has_audio
    assert os.listdir(os.fsencode(out.parent)) == [b"steady \xe9t\xe9.mp4"]
