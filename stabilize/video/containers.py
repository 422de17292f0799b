"""Output containers: the suffix chooses one, and each says what it holds as it is.

A stream the container cannot hold as it is gets transcoded (an audio track into the
container's audio codec, a text subtitle into its subtitle format) with a notice; one it
cannot hold at all (a bitmap subtitle in MP4, any subtitle in AVI) is left out with a
notice. Nothing is dropped silently.

Suffixes not in :data:`CONTAINERS` go to whatever FFmpeg muxer claims them, with the
streams copied; the pre-flight check (:func:`stabilize.video.preflight.check_encoder`)
refuses one that FFmpeg cannot write.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

# Text subtitle codecs (FFmpeg's names): these convert into one another.
TEXT_SUBTITLES = frozenset({"mov_text", "subrip", "srt", "ass", "ssa", "webvtt", "text"})
QUICKTIME_AUDIO = frozenset({"aac", "mp3", "alac", "ac3", "eac3", "opus", "flac"})
# The most channels an audio encoder takes where it is fewer than eight (FFmpeg mixes a
# track of more down to its most): AC-3 holds 5.1, as DVDs carry it
MAX_CHANNELS = {"libmp3lame": 2, "mp2": 2, "ac3": 6}
QUICKTIME = ("-movflags", "+faststart+use_metadata_tags")  # moov first; keep custom tags
# What FFmpeg reads from an MP4's or MOV's ftyp box as the file's metadata: they name the
# source's file type, not the footage, and copied over they were written again as tags
# beside the output's own box (MP4 and MOV read "qt  ;qt  ", and each run added one;
# Matroska wrote MAJOR_BRAND tags)
FILE_TYPE_KEYS = ("major_brand", "minor_version", "compatible_brands")


@dataclass(frozen=True)
class Container:
    """An output container: FFmpeg's muxer, its default video encoder, and the audio and
    subtitle codecs it holds as they are (None: any), with what others become (None:
    left out)."""

    muxer: str
    video_encoder: str = "libx264"
    audio: frozenset[str] | None = None
    audio_encoder: str | None = "aac"
    subtitles: frozenset[str] | None = None
    subtitle_encoder: str | None = None
    chapters: bool = True
    options: tuple[str, ...] = ()
    hevc_tag: str | None = None  # the codec tag Apple players need for HEVC
    # The default encoder for a source of 10 bits or more, where the default one's 10-bit
    # output plays in few players (None: the default one): H.264 at 10 bits (High 10)
    # plays neither on Apple's devices nor in most browsers, HEVC at 10 bits in both
    deep_encoder: str | None = None
    data: frozenset[str] = frozenset()  # data tracks held as they are, by codec tag
    # Where a start timecode goes: "track" (written again from the video's timecode tag
    # as a timecode track: QuickTime's tmcd, MXF's own), "tag" (kept as the video's
    # tag), "" (nowhere)
    timecode: str = ""
    # An image sequence's pictures (OUT a pattern, frames/%05d.png): their pixel formats
    # for an 8-bit source and for a deeper one (None: the pipe's 4:2:0 at its depth)
    pictures: tuple[str, str] | None = None
    name: str = ""  # how notices name it (default: its muxer's name)
    # The encoder's own pixel format, where it takes no 4:2:0 video (GIF's palette)
    pix_fmt: str | None = None
    # FFmpeg filters the video passes before its encoder (GIF's palette)
    video_filter: str = ""
    # Whether a delayed video's timestamps may tick on a 90 kHz clock: MPEG-PS's muxer
    # wrote 24 MB of padding for 2 s of H.264 on one, taking minutes
    fine_clock: bool = True
    # Attached files (the fonts an ASS subtitle track is drawn with), Matroska's alone
    attachments: bool = False
    # Whether it keeps each frame's own time (a variable rate): MXF holds one edit rate
    variable_rate: bool = True
    audio_rate: int | None = None  # the one sample rate its audio takes (Hz; None: any)
    # The most frames from one keyframe to the next (None: the encoder's own): an encoder
    # option, not the muxer's, so not among ``options``, which a remux hands the muxer
    keyframes: int | None = None
    # The encoder for audio of more channels than ``audio_encoder`` takes (None: that
    # one): MP3's and MP2's take two, and downmixed a 5.1 track to stereo
    surround_encoder: str | None = None
    # The least time between frames as its players show them (s; 0: none): browsers show
    # a GIF frame of 0 or 10 ms for 100 ms, so a 60 fps clip played at a third its speed
    min_interval: float = 0.0

    @property
    def timed(self) -> bool:
        """Whether it keeps frame times: an image sequence keeps none."""
        return self.pictures is None

    def audio_codec(self, codec: str, channels: int = 0) -> str | None:
        """``copy`` for an audio codec held as it is, else the encoder a track of
        ``channels`` becomes (None: it cannot be held)."""
        if self.audio is None or codec in self.audio:
            return "copy"
        if self.surround_encoder and channels > MAX_CHANNELS.get(self.audio_encoder or "", 8):
            return self.surround_encoder
        return self.audio_encoder

    def subtitle_codec(self, codec: str) -> str | None:
        """``copy``, the encoder a text subtitle becomes, or None: it cannot be held."""
        if self.subtitles is None or codec in self.subtitles:
            return "copy"
        return self.subtitle_encoder if codec in TEXT_SUBTITLES else None


MP4 = Container(
    "mp4",
    audio=QUICKTIME_AUDIO,
    subtitles=frozenset({"mov_text"}),
    subtitle_encoder="mov_text",
    options=QUICKTIME,
    hevc_tag="hvc1",
    deep_encoder="libx265",
    data=frozenset({"gpmd"}),  # GoPro's GPMF telemetry (its gyro): telemetry-parser reads it back
    timecode="track",
)


def image_sequence(encoder: str, pictures: tuple[str, str]) -> Container:
    """An image sequence written by a picture ``encoder``: no audio, subtitles or
    chapters (each left out with a notice), no frame times."""
    return Container(
        "image2",
        encoder,
        audio=frozenset(),
        audio_encoder=None,
        subtitles=frozenset(),
        chapters=False,
        pictures=pictures,
        name="an image sequence",
    )


def animation(muxer: str, encoder: str, **kwargs) -> Container:
    """An animated picture (GIF): video only, looping for ever, as such pictures play;
    audio, subtitles, data tracks and chapters left out with a notice. (Not animated
    WebP: its frames cannot be restamped with a variable rate's times after encoding.)"""
    return Container(
        muxer,
        encoder,
        audio=frozenset(),
        audio_encoder=None,
        subtitles=frozenset(),
        chapters=False,
        options=("-loop", "0"),
        **kwargs,
    )


# A palette of its own for each frame: one for the whole clip (FFmpeg's default) holds
# every frame back until the last is seen, all of them in memory; dithered by error
# diffusion, which bands least in a camera's smooth skies
GIF_PALETTE = (
    "split[a][b];[a]palettegen=stats_mode=single[p];[b][p]paletteuse=new=1:dither=sierra2_4a"
)

MPEG_TS = Container(
    "mpegts",
    audio=frozenset({"aac", "mp3", "mp2", "ac3", "eac3", "opus"}),
    subtitles=frozenset({"dvb_subtitle"}),
    chapters=False,
    deep_encoder="libx265",
    name="MPEG-TS",
)

MPEG_PS = Container(
    "vob",
    "mpeg2video",
    audio=frozenset({"mp2", "mp3", "ac3", "pcm_dvd"}),
    audio_encoder="mp2",
    surround_encoder="ac3",
    subtitles=frozenset({"dvd_subtitle"}),
    chapters=False,
    pix_fmt="yuv420p",
    fine_clock=False,
    name="MPEG-PS",
)

# Broadcast and editing (an OP1a file, as cameras and editors write): H.264 video, 48 kHz
# PCM audio alone (FFmpeg's muxer: "only 48khz is implemented"), no subtitles or chapters.
# Its index holds each frame's distance from its keyframe in a byte: FFmpeg's default GOP
# (250) failed a clip longer than 129 frames once the work was done ("frame offset (-129)")
MXF = Container(
    "mxf",
    audio=frozenset(),
    audio_encoder="pcm_s24le",
    audio_rate=48_000,
    subtitles=frozenset(),
    chapters=False,
    keyframes=120,
    timecode="track",  # its own timecode track
    variable_rate=False,
    name="MXF",
)

JPEG = image_sequence("mjpeg", ("yuvj420p", "yuvj420p"))  # full range, as JPEG files are
TIFF = image_sequence("tiff", ("rgb24", "rgb48le"))

# The registry: an output suffix → its container. Adding one is a line here.
CONTAINERS: dict[str, Container] = {
    ".mp4": MP4,
    ".m4v": MP4,
    ".mov": replace(MP4, muxer="mov", audio=QUICKTIME_AUDIO | {"pcm_s16le", "pcm_s24le"}),
    ".mkv": Container(
        "matroska",
        subtitles=frozenset(
            {"subrip", "ass", "ssa", "webvtt", "hdmv_pgs_subtitle", "dvd_subtitle", "dvb_subtitle"}
        ),
        subtitle_encoder="srt",
        deep_encoder="libx265",
        timecode="tag",
        attachments=True,
        name="Matroska",
    ),
    ".webm": Container(
        "webm",
        "libvpx-vp9",
        frozenset({"opus", "vorbis"}),
        "libopus",
        frozenset({"webvtt"}),
        "webvtt",
        timecode="tag",
        name="WebM",
    ),
    ".avi": Container(
        "avi",
        audio=frozenset({"mp3", "mp2", "ac3", "pcm_s16le"}),  # not ADTS AAC
        audio_encoder="libmp3lame",
        surround_encoder="ac3",
        subtitles=frozenset(),
        chapters=False,
    ),
    ".ts": MPEG_TS,
    # a camcorder's AVCHD (.MTS) and a Blu-ray's (.m2ts): MPEG-TS in 192-byte packets.
    # FFmpeg took .mts for plain MPEG-TS and wrote a text subtitle into it as a data
    # track no player reads, and refused one in .m2ts
    ".mts": replace(MPEG_TS, options=("-mpegts_m2ts_mode", "1"), name="M2TS"),
    ".m2ts": replace(MPEG_TS, options=("-mpegts_m2ts_mode", "1"), name="M2TS"),
    # OUT a pattern (frames/%05d.png): a picture per frame, at 16 bits a channel for a
    # source of 10 bits or more where the format holds them (PNG, TIFF)
    ".png": image_sequence("png", ("rgb24", "rgb48be")),
    ".jpg": JPEG,
    ".jpeg": JPEG,
    ".tif": TIFF,
    ".tiff": TIFF,
    # a DVD camcorder's, a DVD's: MPEG-2 video at 8 bits, MPEG or AC-3 audio
    ".mpg": MPEG_PS,
    ".mpeg": MPEG_PS,
    ".vob": MPEG_PS,
    ".mxf": MXF,
    # Ogg video, as Firefox plays it: Theora (x264's H.264 it cannot hold) and Vorbis.
    # Theora counts frames at one rate: a variable rate's remux failed ("theora")
    ".ogv": Container(
        "ogg",
        "libtheora",
        frozenset({"vorbis", "opus", "flac"}),
        "libvorbis",
        frozenset(),
        chapters=False,
        variable_rate=False,
        name="Ogg",
    ),
    ".gif": animation(
        "gif", "gif", pix_fmt="pal8", video_filter=GIF_PALETTE, min_interval=0.02, name="GIF"
    ),
}


def container_for(path: str | Path) -> Container:
    """The container an output's suffix names (FFmpeg's own guess for other suffixes)."""
    suffix = Path(path).suffix.lower()
    return CONTAINERS.get(suffix) or Container("", subtitles=None)
