"""The job's settings, and the one place their defaults are written.

The command line takes its defaults from here (``DEFAULTS``), so ``stabilize IN OUT``
and ``stabilize_video(IN, OUT)`` do the same thing.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stabilize.video.encode import Encoding

# A phone's main camera is about 26 mm full-frame equivalent: 69° across the long side,
# however the phone is held. A portrait clip's long side is its height (one re-encoded
# upright; one with a display rotation is worked on as stored): 69° across its width
# would model a 9:16 clip's camera 1.78× too wide, the costly direction (a wrong f's
# keystone grows with |1/f'² - 1/f²|)
DEFAULT_FOV = 69.0
# A lens profile brings its focal length: estimated at a given --fov while warped through
# the profile's, a clip was estimated and warped with two different cameras
LENS_WITH_FOCAL = "--lens brings its own focal length: give it without --fov or --focal"
# Crop at most 13% of each side: about what FFmpeg's vid.stab zooms to (optzoom=1). Where
# removing all the shake would need more, the path keeps as little of it as a linear
# programme finds (:mod:`stabilize.path.optimal`).
DEFAULT_MAX_ZOOM = 1.15
# Undoing a rolling shutter shears and stretches the frame, which the stabilisation
# literature reads as distortion: vid.stab, which does not undo it, reads 0.995–0.998 on
# the real clips, and ours read 0.971 on karma's fastest pans fully corrected, 0.985 on
# phone-cc9 zoomed in. Within 0.8%: 0.991 and 0.992, at 0.491 → 0.444 and 0.527 → 0.619
# px of residual shake (vid.stab 0.611, 0.996) (stabilize.warp.rolling.within_stretch).
# The path keeps a turn's keystone at the frame's middle within the same share, apart:
# karma's middle third, at the 69° default, read 0.974 where the drone turned at its end,
# 0.990 within it (stabilize.path.optimal)
DEFAULT_MAX_STRETCH = 0.8


@dataclass(frozen=True)
class Settings:
    """Everything a stabilisation job can be told; every field has the default a
    user gets from ``stabilize IN OUT``.

    >>> Settings(smooth=1.0).max_zoom
    1.15
    """

    flow: str = "dis"  # flow backend (flow.BACKENDS)
    flow_options: dict = field(default_factory=dict)
    fov: float | str | None = None  # across the long side, degrees; None or "auto": estimated
    focal: float | None = None  # pixels; overrides fov
    smooth: float = 0.5  # smoothing time constant, s
    method: str = "adaptive"  # smoothing method (stabilize.path.smoothing.METHODS)
    # what the warp compensates: the rotation alone, or also the image motion it leaves
    # (stabilize.path.residual.MOTION_MODELS)
    motion: str = "similarity"
    max_zoom: float = DEFAULT_MAX_ZOOM
    crop: str = "auto"  # zoom mode (stabilize.path.zoom.CROP_MODES)
    border: str = "black"  # where a frame has no source (stabilize.warp.border.BORDERS)
    max_deg: float = 15.0  # the estimator's search range per frame pair
    preview: bool = False  # write original | stabilised side by side
    gyro: str | None = None  # a gyro log: the path comes from it, synchronised to the video
    gyro_format: str | None = None
    gyro_offset: float | None = None
    gyro_axes: tuple | None = None  # R_cam_imu as nested tuples
    gyro_lpf: float | None = None  # Hz
    # with a gyro: ms, 'auto', or None: the log's, the lens profile's, else estimated
    readout_ms: float | str | None = None
    # rolling shutter without a gyro: 'auto' (estimated from the video), 'off', or ms
    rolling_shutter: float | str = "auto"
    # the most a rolling shutter's correction may shear or stretch a frame, percent
    # (stabilize.warp.rolling.within_stretch), and apart from it the path's keystone at
    # the frame's middle (stabilize.path.optimal); 100: no limit
    max_stretch: float = DEFAULT_MAX_STRETCH
    gyro_drift: bool = False  # also fit a linear clock drift
    # Where the log's motion does not match the video's, stabilise from the video's own
    # instead of refusing: batch --gyro auto's, for the gyro a camera records in its
    # clips, which one stabilised in the camera (a GoPro's HyperSmooth) does not match
    gyro_fallback: bool = False
    gyro_timestamps: str | None = None  # frame times on the gyro clock (a file)
    gyro_search: float = 1.0  # offset search range, ± s (a log on its own clock: all of it)
    lens: str | None = None  # a Gyroflow lens profile (OpenCV fisheye)
    device: str = "cpu"  # where frames are warped: cpu (OpenCV) or cuda (kornia, batched)
    size: tuple[int, int] | None = None  # output (H, W); default: the input's
    # interlaced input (stabilize.video.fields): 'auto' deinterlaces a stream flagged
    # interlaced, 'on' every stream (one flagged progressive but combed), 'off' none
    deinterlace: str = "auto"
    # black bars baked into the frame (stabilize.video.bars): 'auto' stabilises the
    # picture inside them and keeps them still, 'off' warps them with it
    bars: str = "auto"
    # an image-sequence input's frame rate (frames/img-%d.jpg); None: 30. A video's own
    # frame times are always used
    fps: float | None = None
    encoding: Encoding = field(default_factory=Encoding)

    def focal_px(self, size: tuple[int, int]) -> float:
        """The focal length in pixels for frames of ``size`` (h, w): ``focal``; else
        ``fov``, or ``DEFAULT_FOV``, across the long side (a camera's field of view as
        its maker quotes it, the one across a level frame, however it was held)."""
        if self.focal is not None:
            return float(self.focal)
        from rotation.camera import focal_from_fov  # the estimator's package is heavy

        given = isinstance(self.fov, int | float)
        return focal_from_fov(self.fov if given else DEFAULT_FOV, max(size))

    @property
    def fov_given(self) -> bool:
        """Whether the focal length was given (``fov`` in degrees, or ``focal``)."""
        return self.focal is not None or isinstance(self.fov, int | float)


DEFAULTS = Settings()
