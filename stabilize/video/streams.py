"""Keeping what the user gave us: every audio and subtitle track of the source, its
chapters and its metadata, and the data tracks and attached files the container can hold
(GoPro's GPMF telemetry in MP4 and MOV, an ASS subtitle track's fonts in Matroska), muxed
beside the stabilised video.

Each track is copied when the output container holds it as it is, transcoded when it
does not (AAC into WebM becomes Opus, mov_text into MKV becomes SRT), and left out only
when the container cannot hold it at all, with a notice saying so. Per-stream metadata
(language, title) comes with each track; the file's (creation time, location, title)
and the video stream's own come from the source. The display rotation does not: the
frames are written upright. A start timecode (a camera's tmcd track, or a timecode tag)
is set on the video, from which MP4 and MOV write a timecode track again; Matroska and
WebM keep it as the video's tag, and other containers lose it, with a notice.
"""

from __future__ import annotations

from stabilize.video.binary import local
from stabilize.video.containers import FILE_TYPE_KEYS, MAX_CHANNELS, Container
from stabilize.video.encode import Mux
from stabilize.video.probe import Stream, VideoInfo


def keep_streams(info: VideoInfo, container: Container, video_delay: float = 0.0) -> Mux:
    """The :class:`Mux` that carries the source's tracks, chapters and metadata over.

    ``video_delay`` (s): how late the source's video starts after its first stream, so
    that audio stays in sync.
    """
    if info.input_args:  # an image sequence: no other streams, no metadata
        return Mux()
    args: list[str] = []
    notices: list[str] = []
    count = {"a": 0, "s": 0, "d": 0, "t": 0}
    kept: list[int] = []
    timecode = _timecode(info)
    for stream in info.streams:
        if _rebuilt(stream, info, container):
            continue
        codec, flag = _codec(stream, container)
        where = _name(container)
        if stream.kind == "video":
            notices.append(_video_left_out(stream))
            continue
        if codec is None:
            # GoPro's fdsc has no codec, only a tag; an attached font, only its name
            what = stream.filename or (stream.codec if stream.codec != "none" else stream.tag)
            notices.append(
                f"left out {stream.kind} #{stream.index} ({what}): {where} cannot hold it"
                + (_where_timecode(timecode, container) if _is_timecode(stream) else "")
            )
            continue
        if codec != "copy":
            notices.append(
                f"{stream.kind} #{stream.index}: {stream.codec} → {codec} for {where}"
                + _downmix(stream, codec)
            )
        args += ["-map", f"1:{stream.index}", f"-c:{flag}:{count[flag]}", codec]
        if flag == "a" and codec != "copy" and container.audio_rate:
            args += [f"-ar:a:{count[flag]}", str(container.audio_rate)]
        count[flag] += 1
        kept.append(stream.index)
    # One mapping per stream: any explicit one turns FFmpeg's per-stream default off.
    args += ["-map_metadata", "1", "-map_metadata:s:0", f"1:s:{_first_video(info)}"]
    for key in FILE_TYPE_KEYS:  # an empty value leaves the key out
        args += ["-metadata", f"{key}="]
    if timecode:
        args += ["-metadata:s:0", f"timecode={timecode}"]
    titles = {s.index: s.title for s in info.streams}
    for out, index in enumerate(kept, start=1):
        args += [f"-map_metadata:s:{out}", f"1:s:{index}"]
        if titles[index]:
            args += [f"-metadata:s:{out}", f"title={titles[index]}"]
    args += ["-map_chapters", "1" if container.chapters else "-1"]
    return Mux((("-i", local(info.path)),), tuple(args), tuple(notices), video_delay)


def _codec(stream: Stream, container: Container) -> tuple[str | None, str]:
    """(``copy``, the encoder it becomes, or None: it cannot be held; FFmpeg's stream
    letter) of a source stream in ``container``."""
    if stream.kind == "audio":
        return container.audio_codec(stream.codec, stream.channels), "a"
    if stream.kind == "subtitle":
        return container.subtitle_codec(stream.codec), "s"
    if stream.kind == "attachment":
        return ("copy" if container.attachments else None), "t"
    held = stream.kind == "data" and stream.tag in container.data
    return ("copy" if held else None), "d"


def _downmix(stream: Stream, codec: str) -> str:
    """What the notice of a transcoded track adds where its encoder takes fewer channels
    than it has: FFmpeg mixes it down (7.1 into AVI's AC-3: 5.1)."""
    most = MAX_CHANNELS.get(codec)
    if most is None or stream.channels <= most:
        return ""
    return f", its {stream.channels} channels mixed down to {most}"


def _video_left_out(stream: Stream) -> str:
    """The notice for a video stream other than the stabilised one."""
    if stream.cover:  # a thumbnail, as yt-dlp embeds one
        # FFmpeg writes a cover only as MP4's iTunes-style cover atom, which the QuickTime
        # metadata keys that carry a phone's tags rule out; it drops one in MOV, and makes
        # one a video track of a single frame in Matroska
        return f"left out the cover picture (#{stream.index}, {stream.codec}): covers are not kept"
    what = f"video #{stream.index} ({stream.codec})"  # a second camera's, a proxy's
    return f"left out {what}: only the first video stream is stabilised"


def _rebuilt(stream: Stream, info: VideoInfo, container: Container) -> bool:
    """Whether a stream not carried over is in the output anyway: the video itself,
    MP4's chapter text track (the chapters are written from the chapter list), or a
    timecode track the container writes again from the video's timecode."""
    if stream.kind == "video":
        return stream.index == _first_video(info)
    if _is_timecode(stream):
        return container.timecode == "track"
    return stream.kind == "data" and stream.tag == "text" and info.chapters > 0


def _is_timecode(stream: Stream) -> bool:
    return stream.kind == "data" and stream.tag == "tmcd" and bool(stream.timecode)


def _timecode(info: VideoInfo) -> str:
    """The source's start timecode: its video's, else its timecode track's, else none."""
    video = [s.timecode for s in info.streams if s.kind == "video" and s.timecode]
    track = [s.timecode for s in info.streams if _is_timecode(s)]
    return next(iter(video + track), "")


def _where_timecode(timecode: str, container: Container) -> str:
    if container.timecode == "tag":
        return f"; its timecode ({timecode}) is kept as the video's tag"
    return f"; its timecode ({timecode}) is lost"


def _first_video(info: VideoInfo) -> int:
    return next((s.index for s in info.streams if s.kind == "video"), -1)


def _name(container: Container) -> str:
    return container.name or (container.muxer.upper() if container.muxer else "this container")
