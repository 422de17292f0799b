"""Every stream kept: audio tracks, subtitle tracks, chapters and metadata, checked by
count and by content, into MKV and MP4 outputs; and the container the suffix names."""

from __future__ import annotations

import subprocess
from fractions import Fraction
from pathlib import Path

import av
import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.video import Encoding, FrameWriter, ffmpeg_exe, frame_times, probe, read_frames
from stabilize.video.containers import container_for
from stabilize.video.preflight import OutputError, check_times
from stabilize.video.streams import keep_streams
from tests.stabilize.helpers import SAMPLE

SUBTITLES = {"eng": "Hello street", "fra": "Bonjour la rue"}
CHAPTERS = ("Start", "Corner")


@pytest.fixture(scope="module")
def rich(shaky, tmp_path_factory) -> dict[str, Path]:
    """The shaky clip with 2 audio tracks, 2 subtitle tracks, chapters and metadata, as
    MKV (SubRip) and MP4 (mov_text)."""
    folder = tmp_path_factory.mktemp("rich")
    for lang, text in SUBTITLES.items():
        (folder / f"{lang}.srt").write_text(f"1\n00:00:00,200 --> 00:00:01,500\n{text}\n")
    (folder / "chapters.txt").write_text(
        ";FFMETADATA1\ntitle=Street walk\n"
        f"[CHAPTER]\nTIMEBASE=1/1000\nSTART=0\nEND=1000\ntitle={CHAPTERS[0]}\n"
        f"[CHAPTER]\nTIMEBASE=1/1000\nSTART=1000\nEND=2000\ntitle={CHAPTERS[1]}\n"
    )
    mkv = folder / "rich.mkv"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky)]
    cmd += ["-f", "lavfi", "-i", "sine=frequency=880:duration=2"]
    cmd += ["-i", str(folder / "eng.srt"), "-i", str(folder / "fra.srt")]
    cmd += ["-i", str(folder / "chapters.txt")]
    cmd += ["-map", "0:v", "-map", "0:a", "-map", "1:a", "-map", "2", "-map", "3"]
    cmd += ["-map_metadata", "4", "-map_chapters", "4", "-c:v", "copy", "-c:a", "aac"]
    cmd += ["-c:s", "srt", "-metadata", "creation_time=2024-05-01T10:00:00Z"]
    cmd += ["-metadata", "location=+48.8584+002.2945/"]
    cmd += ["-metadata:s:a:0", "language=eng", "-metadata:s:a:1", "language=fra"]
    cmd += ["-metadata:s:a:1", "title=Commentary"]
    cmd += ["-metadata:s:s:0", "language=eng", "-metadata:s:s:1", "language=fra", str(mkv)]
    subprocess.run(cmd, check=True)
    mp4 = folder / "rich.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(mkv), "-map", "0", "-c", "copy"]
    subprocess.run(
        [*cmd, "-c:s", "mov_text", "-movflags", "use_metadata_tags", str(mp4)], check=True
    )
    return {"mkv": mkv, "mp4": mp4}


def subtitle_text(path: Path, k: int) -> str:
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(path), "-map", f"0:s:{k}", "-f", "srt", "-"]
    return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout


def streams(path: Path) -> dict[str, list[dict]]:
    with av.open(str(path)) as c:
        return {
            kind: [dict(s.metadata) for s in c.streams if s.type == kind]
            for kind in ("video", "audio", "subtitle")
        } | {"file": [dict(c.metadata)], "chapters": [dict(ch) for ch in c.chapters()]}


def said_of_tracks(summary: dict) -> list[str]:
    """The summary's notices but for what the run measured (its rolling shutter)."""
    return [n for n in summary["notices"] if not n.startswith("rolling shutter")]


PAIRS = [(src, suffix) for src in ("mkv", "mp4") for suffix in (".mkv", ".mp4")]


@pytest.fixture(scope="module", params=PAIRS, ids=lambda p: f"{p[0]}-to-{p[1][1:]}")
def kept(request, rich, tmp_path_factory) -> tuple[Path, dict, dict]:
    """(output, summary, its streams) of the rich clip stabilised into each container."""
    source, suffix = request.param
    out = tmp_path_factory.mktemp("kept") / f"out{suffix}"
    summary, _ = stabilize_video(rich[source], out, Settings(fov=70.0))
    said = said_of_tracks(summary)
    if source == suffix[1:]:
        assert not said  # everything fitted as it was
    else:  # SubRip ↔ mov_text, said so
        assert len(said) == 2 and all("→" in n for n in said)
    return out, summary, streams(out) | {"source": [streams(rich[source])["file"][0]]}


def test_every_audio_track_is_kept(kept):
    _, summary, got = kept
    assert len(got["video"]) == 1 and summary["frames"] == 60
    assert [s.get("language") for s in got["audio"]] == ["eng", "fra"]
    assert any("Commentary" in s.values() for s in got["audio"][1:])


def test_every_subtitle_track_is_kept_with_its_text(kept):
    out, _, got = kept
    assert [s.get("language") for s in got["subtitle"]] == ["eng", "fra"]
    for k, text in enumerate(SUBTITLES.values()):
        assert text in subtitle_text(out, k)


def test_the_chapters_are_kept(kept):
    assert [ch["metadata"]["title"] for ch in kept[2]["chapters"]] == list(CHAPTERS)


def test_the_files_metadata_is_kept(kept):
    tags = {k.lower(): v for k, v in kept[2]["file"][0].items()}
    assert tags["title"] == "Street walk" and tags["location"] == "+48.8584+002.2945/"
    if "creation_time" in kept[2]["source"][0]:
        assert tags["creation_time"].startswith("2024-05-01T10:00:00")


def test_the_source_files_type_is_not_copied_as_tags(kept):
    # the source's ftyp box, read as metadata, was written again as tags: MP4 then read
    # "isom;isom" (one more each run) and Matroska carried MAJOR_BRAND
    tags = {k.lower(): v for k, v in kept[2]["file"][0].items()}
    if kept[0].suffix == ".mkv":
        assert not {"major_brand", "minor_version", "compatible_brands"} & tags.keys()
    else:
        assert ";" not in tags["major_brand"] + tags["minor_version"]


def test_the_video_is_the_default_track(kept):
    # Matroska marked the piped video not the default, which players read as "not shown"
    with av.open(str(kept[0])) as c:
        assert c.streams.video[0].disposition & av.stream.Disposition.default
        assert c.streams.audio[0].disposition & av.stream.Disposition.default


def test_webm_transcodes_what_it_cannot_hold_and_says_so(rich, tmp_path):
    info = probe(rich["mp4"])
    mux = keep_streams(info, container_for("out.webm"))
    assert any("aac → libopus" in n for n in mux.notices)
    assert any("mov_text → webvtt" in n for n in mux.notices)
    out = tmp_path / "out.webm"
    stabilize_video(rich["mp4"], out, Settings(fov=70.0))
    with av.open(str(out)) as c:
        assert c.format.name.startswith("matroska")
        assert c.streams.video[0].codec_context.name == "vp9"
        assert [s.codec_context.name for s in c.streams.audio] == ["opus", "opus"]
        assert len(c.streams.subtitles) == 2


def test_avi_cannot_hold_subtitles_and_says_so(rich):
    mux = keep_streams(probe(rich["mkv"]), container_for("out.avi"))
    assert sum("left out subtitle" in n for n in mux.notices) == 2


@pytest.mark.parametrize("suffix", [".avi", ".mpg"])
def test_surround_sound_stays_surround_in_avi_and_mpeg_ps(shaky, tmp_path, suffix):
    # MP3 and MP2 take two channels: a 5.1 track was mixed down to stereo, unsaid
    clip = tmp_path / "surround.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-f", "lavfi", "-i"]
    cmd += ["sine=d=2,aformat=channel_layouts=5.1|7.1", "-ac:a:0", "6", "-ac:a:1", "8"]
    cmd += ["-map", "0:v", "-map", "1:a", "-map", "1:a", "-c:v", "copy", "-c:a", "aac"]
    subprocess.run([*cmd, str(clip)], check=True)
    info, out = probe(clip), tmp_path / f"out{suffix}"
    assert [s.channels for s in info.streams] == [0, 6, 8]
    mux = keep_streams(info, container_for(out))
    assert mux.notices[0].startswith("audio #1: aac → ac3 for")
    assert mux.notices[1].endswith(", its 8 channels mixed down to 6")
    with FrameWriter(out, (64, 64), 25.0, Encoding(), mux) as writer:
        for _ in range(3):
            writer.write(np.zeros(writer.shape, writer.dtype))
    with av.open(str(out)) as c:
        assert [(a.codec_context.name, a.channels) for a in c.streams.audio] == [("ac3", 6)] * 2
    stereo = keep_streams(probe(shaky), container_for(out))  # as it was: MP3, MP2
    assert stereo.notices[0].split(" → ")[1].split()[0] in ("libmp3lame", "mp2")


def test_a_second_video_stream_is_left_out_and_said_so(shaky, tmp_path):
    two = tmp_path / "two.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-map", "0:v", "-map", "0:v"]
    subprocess.run([*cmd, "-map", "0:a", "-c", "copy", str(two)], check=True)
    mux = keep_streams(probe(two), container_for("out.mp4"))
    assert mux.notices == ("left out video #1 (h264): only the first video stream is stabilised",)


def test_the_first_video_stream_is_the_one_decoded_when_a_larger_one_follows(shaky, tmp_path):
    # a dashcam's rear camera first, its front camera, larger, second: FFmpeg's own choice
    # is the largest, which was read at the first one's size, garbled
    rear = tmp_path / "rear.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-t", "1", "-vf", "scale=160:90"]
    subprocess.run([*cmd, "-an", str(rear)], check=True)
    two = tmp_path / "two.mkv"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(rear), "-i", str(shaky), "-map", "0:v"]
    subprocess.run([*cmd, "-map", "1:v", "-c", "copy", str(two)], check=True)
    info = probe(two)
    assert info.size == (90, 160)
    got, want = next(read_frames(two, info=info)), next(read_frames(rear))
    assert np.abs(got.astype(int) - want).mean() < 1


def test_hevc_in_mp4_is_tagged_hvc1(tmp_path):
    out = tmp_path / "h.mp4"
    encoding = Encoding(codec="libx265", preset="ultrafast")
    with FrameWriter(out, (64, 64), 30.0, encoding) as writer:
        for _ in range(3):
            writer.write(np.zeros((64, 64, 3), np.uint8))
    assert probe(out).streams[0].tag == "hvc1"


MUXERS = {".mp4": "mp4", ".m4v": "mp4", ".mov": "mov", ".mkv": "matroska", ".webm": "webm"}
MUXERS |= {".avi": "avi", ".ts": "mpegts", ".gif": "gif", ".mpg": "vob", ".vob": "vob"}
MUXERS |= {".mxf": "mxf"}
MUXERS |= {".unknown": ""}


@pytest.mark.parametrize(("suffix", "muxer"), list(MUXERS.items()))
def test_the_suffix_names_the_container(suffix, muxer):
    assert container_for(f"out{suffix.upper()}").muxer == muxer


def test_gopro_telemetry_is_kept(shared, tmp_path):
    # GPMF, the camera's own gyro, as a data track: copied into MP4 and read back whole.
    telemetry_parser = pytest.importorskip("telemetry_parser")
    cut = tmp_path / "karma.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shared / "data" / "gopro" / "karma.mp4")]
    cmd += ["-map", "0:v", "-map", "0:a", "-map", "0:3", "-c", "copy", "-t", "2", str(cut)]
    subprocess.run(cmd, check=True)
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(cut, out, Settings(fov=100.0))
    assert not any("gpmd" in n or "bin_data" in n for n in summary["notices"])
    before = len(telemetry_parser.Parser(str(cut)).normalized_imu())
    assert before > 500 and len(telemetry_parser.Parser(str(out)).normalized_imu()) == before


TIMECODE = "01:02:03:04"


@pytest.fixture(scope="module")
def timecoded(shaky, tmp_path_factory) -> Path:
    """The shaky clip with a start timecode: a tmcd track, as cameras write."""
    out = tmp_path_factory.mktemp("timecode") / "tc.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky), "-map", "0:v", "-c", "copy"]
    subprocess.run([*cmd, "-timecode", TIMECODE, str(out)], check=True)
    assert [(s.tag, s.timecode) for s in probe(out).streams if s.kind == "data"] == [
        ("tmcd", TIMECODE)
    ]
    return out


def test_the_timecode_track_is_written_again_in_mp4(timecoded, tmp_path):
    out = tmp_path / "out.mp4"
    summary, _ = stabilize_video(timecoded, out, Settings(fov=70.0))
    assert not said_of_tracks(summary)  # not "left out": the muxer writes it from the tag
    tracks = [(s.tag, s.timecode) for s in probe(out).streams if s.kind == "data"]
    assert tracks == [("tmcd", TIMECODE)]


def test_matroska_keeps_the_timecode_as_the_videos_tag_and_says_so(timecoded, tmp_path):
    out = tmp_path / "out.mkv"
    summary, _ = stabilize_video(timecoded, out, Settings(fov=70.0))
    assert [n for n in summary["notices"] if "tmcd" in n] == [
        f"left out data #1 (tmcd): Matroska cannot hold it; its timecode ({TIMECODE}) is kept "
        "as the video's tag"
    ]
    assert probe(out).streams[0].timecode == TIMECODE


def test_a_timecode_no_container_holds_is_said_lost(timecoded):
    mux = keep_streams(probe(timecoded), container_for("out.avi"))
    assert [n for n in mux.notices if "tmcd" in n] == [
        f"left out data #1 (tmcd): AVI cannot hold it; its timecode ({TIMECODE}) is lost"
    ]


@pytest.fixture(scope="module")
def attached(shaky, tmp_path_factory) -> Path:
    """The shaky clip at a variable frame rate as Matroska, with an ASS subtitle track,
    the font it is drawn with attached, and a cover picture (as yt-dlp embeds one)."""
    folder = tmp_path_factory.mktemp("attached")
    (folder / "s.srt").write_text("1\n00:00:00,200 --> 00:00:01,500\nHello street\n")
    cover = folder / "cover.png"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-f", "lavfi", "-i", "testsrc=s=64x64"]
    subprocess.run([*cmd, "-frames:v", "1", str(cover)], check=True)
    (folder / "font.ttf").write_bytes(FONT)
    out = folder / "attached.mkv"
    cmd = [ffmpeg_exe(), "-v", "error", "-y", "-i", str(shaky), "-i", str(folder / "s.srt")]
    cmd += ["-map", "0:v", "-map", "0:a", "-map", "1", "-c:a", "copy", "-c:s", "ass"]
    cmd += ["-vf", "setpts=(N+0.4*mod(N\\,3))/30/TB", "-fps_mode", "passthrough"]
    for k, (path, mime) in enumerate(((folder / "font.ttf", "font/ttf"), (cover, "image/png"))):
        cmd += ["-attach", str(path), f"-metadata:s:t:{k}", f"mimetype={mime}"]
    subprocess.run([*cmd, str(out)], check=True)
    kinds = [(s.kind, s.cover) for s in probe(out).streams]
    assert kinds[3:] == [("attachment", False), ("video", True)]
    return out


FONT = b"\x00\x01\x00\x00" + bytes(range(256)) * 4  # kept byte for byte, not parsed


def test_attached_files_are_kept_in_matroska_and_a_cover_is_said_left_out(attached, tmp_path):
    # The fonts an ASS track is drawn with: "Matroska cannot hold it", they were left out
    out = tmp_path / "out.mkv"
    summary, _ = stabilize_video(attached, out, Settings(fov=70.0))
    assert said_of_tracks(summary) == ["left out the cover picture (#4, png): covers are not kept"]
    with av.open(str(out)) as c:
        fonts = [s for s in c.streams if s.type == "attachment"]
        assert [(s.name, s.mimetype, bytes(s.data)) for s in fonts] == [
            ("font.ttf", "font/ttf", FONT)
        ]
        assert c.streams.video[0].disposition & av.stream.Disposition.default
        assert c.streams.audio[0].disposition & av.stream.Disposition.default  # retimed
    assert np.ptp(np.diff(frame_times(out))) > 0.01  # the variable rate's own remux


def test_attached_files_no_container_but_matroska_holds_are_said_left_out(attached):
    mux = keep_streams(probe(attached), container_for("out.mp4"))
    assert "left out attachment #3 (font.ttf): MP4 cannot hold it" in mux.notices


def test_a_gif_keeps_every_frame_and_its_time_and_loops(attached, tmp_path):
    # "FFmpeg cannot write libx264 as .gif" before; the source here runs at a variable rate
    out = tmp_path / "out.gif"
    summary, _ = stabilize_video(attached, out, Settings(fov=70.0))
    assert summary["encoder"] == {"codec": "gif", "pix_fmt": "pal8"}
    assert sum("GIF cannot hold it" in n for n in summary["notices"]) == 3  # audio, ASS, font
    times = frame_times(attached)
    np.testing.assert_allclose(frame_times(out), times, atol=0.006)  # GIF's centiseconds
    from PIL import Image

    with Image.open(out) as gif:
        assert gif.n_frames == 60 and gif.info["loop"] == 0  # for ever
    # its palette of 256 colours a frame keeps the picture: as the MP4's, within a few levels
    mp4 = tmp_path / "out.mp4"
    stabilize_video(attached, mp4, Settings(fov=70.0, encoding=Encoding(crf=0)))
    pairs = zip(read_frames(out), read_frames(mp4), strict=True)
    gaps = [np.abs(a.astype(int) - b).mean() for a, b in pairs]
    assert len(gaps) == 60 and max(gaps) < 4


def test_a_gif_of_a_60_fps_clip_keeps_every_frame_browsers_show(shaky, tmp_path):
    # its delays alternated 10 and 20 ms, and browsers show a 10 ms frame for 100 ms: the
    # clip played at a third of its speed
    fast = tmp_path / "fast.mp4"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-vf", "setpts=N/60/TB", "-r", "60"]
    subprocess.run([*cmd, "-an", str(fast)], check=True)
    out, n = tmp_path / "out.gif", len(frame_times(fast))
    summary, _ = stabilize_video(fast, out, Settings(fov=70.0))
    half = (n + 1) // 2  # every other frame, the first and the last among them
    assert summary["frames"] == half and f"{half} of {n} frames" in " ".join(summary["notices"])
    from PIL import Image

    with Image.open(out) as gif:
        delays = [gif.seek(k) or gif.info["duration"] for k in range(gif.n_frames)]
    assert min(delays) >= 20 and sum(delays) == pytest.approx(half * 1000 / 30, abs=10)


def test_a_gif_says_it_carries_alpha_only_where_it_declares_transparency(shaky, tmp_path):
    # FFmpeg decodes every GIF as bgra: an opaque one was said to lose its alpha
    opaque, clear = tmp_path / "opaque.gif", tmp_path / "clear.gif"
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(shaky), "-frames:v", "5"]
    subprocess.run([*cmd, str(opaque)], check=True)
    keyed = "format=rgba,colorkey=0x808080:0.4,split[a][b];[a]palettegen=reserve_transparent=1[p];"
    keyed += "[b][p]paletteuse=alpha_threshold=128"
    subprocess.run([*cmd, "-filter_complex", keyed, str(clear)], check=True)
    assert [(probe(p).pix_fmt, probe(p).alpha) for p in (opaque, clear)] == [
        ("bgra", False),
        ("bgra", True),
    ]


def test_a_variable_rate_phone_clip_keeps_its_tags_and_plays_on_apples_players(tmp_path):
    # a variable rate is remuxed with its own times, which wrote neither the phone's tags
    # (its location among them) nor the index first, tagged HEVC hev1, which Apple's
    # players do not play, and failed on a timecode track ("Invalid argument") and on
    # chapters ("Invalid data found when processing input")
    clip, out = tmp_path / "phone.mov", tmp_path / "out.mov"
    chapters = tmp_path / "chapters.txt"
    chapters.write_text(
        ";FFMETADATA1\n[CHAPTER]\nTIMEBASE=1/1000\nSTART=0\nEND=1000\ntitle=Start\n"
        "[CHAPTER]\nTIMEBASE=1/1000\nSTART=1000\nEND=2000\ntitle=Corner\n"
    )
    tags = {
        "com.apple.quicktime.location.ISO6709": "+48.8584+002.2945+035.000/",
        "com.apple.quicktime.make": "Apple",
    }
    cmd = [ffmpeg_exe(), "-v", "error", "-i", str(SAMPLE / "clip.mp4"), "-i", str(chapters)]
    cmd += ["-map", "0", "-map_chapters", "1", "-c:a", "copy"]
    cmd += ["-vf", "setpts=(N+0.4*mod(N\\,3))/30/TB", "-enc_time_base:v", "1:90000"]
    for key, value in tags.items():
        cmd += ["-metadata", f"{key}={value}"]
    cmd += ["-timecode", "01:02:03:04", "-movflags", "use_metadata_tags"]
    subprocess.run([*cmd, str(clip)], check=True)
    stabilize_video(clip, out, Settings(fov=70.0, encoding=Encoding(codec="libx265")))
    assert np.ptp(np.diff(frame_times(out))) > 0.01  # remuxed at its variable rate
    with av.open(str(out)) as c:
        assert tags.items() <= dict(c.metadata).items()
        assert ";" not in c.metadata["major_brand"]  # its own file type only, once
        assert c.streams.video[0].codec_tag == "hvc1"
        assert c.streams.video[0].metadata["timecode"] == "01:02:03:04"
        timecodes = [s.metadata.get("timecode") for s in c.streams.data]
        assert "01:02:03:04" in timecodes  # its tmcd track
        assert [ch["metadata"]["title"] for ch in c.chapters()] == ["Start", "Corner"]
    data = out.read_bytes()
    assert data.find(b"moov") < data.find(b"mdat")  # the index first (+faststart)


@pytest.mark.parametrize("suffix", [".mts", ".m2ts"])
def test_avchd_and_blu_ray_suffixes_write_m2ts(rich, tmp_path, suffix):
    # .mts was plain MPEG-TS with a text subtitle written as a data track no player reads,
    # and .m2ts refused the subtitle ("Cannot automatically assign PID")
    info, out = probe(rich["mp4"]), tmp_path / f"out{suffix}"
    mux = keep_streams(info, container_for(out))
    assert "left out subtitle #3 (mov_text): M2TS cannot hold it" in mux.notices
    with FrameWriter(out, info.size, 30.0, Encoding(), mux) as writer:
        for _ in range(3):
            writer.write(np.zeros(writer.shape, writer.dtype))
    data = out.read_bytes()
    assert len(data) % 192 == 0 and data[4::192][:100] == b"\x47" * 100  # 192-byte packets


def test_mxf_takes_a_long_clip_and_its_audio_as_48_khz_pcm(rich, tmp_path):
    # AAC audio was refused ("only 48khz is implemented"), and a clip of more than 129
    # frames failed once the work was done ("frame offset (-129) ... reduce encoder GOP")
    info, out, long = probe(rich["mp4"]), tmp_path / "out.mxf", tmp_path / "long.mxf"
    mux = keep_streams(info, container_for(out))
    assert "audio #1: aac → pcm_s24le for MXF" in mux.notices
    assert "left out subtitle #3 (mov_text): MXF cannot hold it" in mux.notices
    fast = Encoding(preset="ultrafast")
    for path, frames, with_tracks in ((out, 60, mux), (long, 140, None)):
        with FrameWriter(path, (64, 64), 30000 / 1001, fast, with_tracks) as writer:
            for _ in range(frames):
                writer.write(np.zeros(writer.shape, writer.dtype))
    with av.open(str(out)) as c:
        video, audio = c.streams.video[0], c.streams.audio
        assert (video.codec_context.name, video.average_rate) == ("h264", Fraction(30000, 1001))
        assert [(a.codec_context.name, a.sample_rate) for a in audio] == [("pcm_s24le", 48000)] * 2
    with av.open(str(long)) as c:
        assert sum(1 for packet in c.demux(c.streams.video[0]) if packet.size) == 140


def test_ogv_writes_theora_and_vorbis(rich, tmp_path):
    # x264's H.264 was refused by the Ogg muxer ("Unsupported codec id in stream 0")
    info, out = probe(rich["mp4"]), tmp_path / "out.ogv"
    mux = keep_streams(info, container_for(out))
    assert "audio #1: aac → libvorbis for Ogg" in mux.notices
    assert "left out subtitle #3 (mov_text): Ogg cannot hold it" in mux.notices
    with FrameWriter(out, (64, 64), 30.0, Encoding(), mux) as writer:
        for _ in range(30):
            writer.write(np.zeros(writer.shape, writer.dtype))
    with av.open(str(out)) as c:
        assert c.streams.video[0].codec_context.name == "theora"
        assert [a.codec_context.name for a in c.streams.audio] == ["vorbis"] * 2
        assert [a.language for a in c.streams.audio] == ["eng", "fra"]
    assert len(frame_times(out)) == 30  # (a repeated frame is an empty packet in Theora)
    times = np.r_[np.arange(10) / 30, 0.4 + np.arange(10) / 10]  # a phone's varying rate
    with pytest.raises(OutputError, match="Ogg holds one constant frame rate"):
        check_times(out, times)


def test_mxf_writes_the_timecode_in_its_own_track(timecoded, tmp_path):
    out = tmp_path / "out.mxf"
    mux = keep_streams(probe(timecoded), container_for(out))
    assert not mux.notices  # not "left out data #1 (tmcd)": MXF writes its own
    with FrameWriter(out, (64, 64), 30.0, Encoding(preset="ultrafast"), mux) as writer:
        for _ in range(3):
            writer.write(np.zeros(writer.shape, writer.dtype))
    with av.open(str(out)) as c:
        assert c.metadata["timecode"] == TIMECODE  # the material package's timecode
