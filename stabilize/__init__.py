"""The stabiliser: two streaming passes over a video, memory independent of its length.

>>> from stabilize import stabilize_video, Settings
>>> settings = Settings(smooth=1.0, max_zoom=1.3)
>>> summary, path = stabilize_video("shaky.mp4", "steady.mp4", settings)  # doctest: +SKIP
>>> summary["frames"], summary["zoom"], path.smooth.shape  # doctest: +SKIP
(300, 1.21, (300, 3, 3))

The stages, for a library user who wants one of them alone:

* :func:`probe` and :func:`read_frames` (:mod:`stabilize.video`): what a video is, and
  its frames;
* :func:`estimate_rotations` (:mod:`stabilize.motion`): pass 1, each frame pair's camera
  rotation, as a :class:`VisualTrack`;
* :func:`estimate_readout` (:mod:`stabilize.shutter`): a rolling shutter's readout from
  a track's band rotations (pass 1 with ``bands``), and the attitude fitted at it;
* :func:`plan_path` (:mod:`stabilize.path`): the smoothed path within the zoom budget,
  as a :class:`CameraPath`;
* :func:`render` (:mod:`stabilize.warp`): pass 2, the frames warped along that path;
* :func:`evaluate_pair` (:mod:`stabilize.evaluate`): the literature's quality metrics.

The names are imported when first used, so ``import stabilize`` stays cheap.
"""

from __future__ import annotations

from stabilize.lazy import lazy_exports

_EXPORTS = {
    "Settings": "stabilize.settings",
    "stabilize_video": "stabilize.pipeline",
    "probe": "stabilize.video",
    "read_frames": "stabilize.video",
    "VideoError": "stabilize.video",
    "estimate_rotations": "stabilize.motion.estimate",
    "VisualTrack": "stabilize.motion.track",
    "estimate_readout": "stabilize.shutter.readout",
    "plan_path": "stabilize.path.plan",
    "CameraPath": "stabilize.warp.camera_path",
    "render": "stabilize.warp.render",
    "evaluate_pair": "stabilize.evaluate.metrics",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = lazy_exports("stabilize", _EXPORTS)
