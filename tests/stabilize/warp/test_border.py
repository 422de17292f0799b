"""What fills the output where a frame has no source: black, its edge, or its mirror
image, alike on every warp (homography or map, RGB or I420, OpenCV or torch)."""

import numpy as np
import pytest

from stabilize import Settings, stabilize_video
from stabilize.pipeline import check_settings
from stabilize.video import i420, probe, read_frames
from stabilize.warp.cuda import remap_frames_torch, warp_frames_torch
from stabilize.warp.frames import warp_frame
from stabilize.warp.planes import remap_planes, warp_planes
from stabilize.warp.remap import coarse_map, remap_from
from stabilize.warp.sources import rolling_source
from tests.stabilize.helpers import from_rgb

SHIFT = np.array([[1.0, 0, 6], [0, 1, 0], [0, 0, 1]])  # input x → output x + 6


def ramp(h: int = 40, w: int = 60) -> np.ndarray:
    """Columns of distinct greys (and rows of distinct reds), to tell edge from mirror."""
    x, y = np.meshgrid(np.arange(w), np.arange(h))
    return np.stack([40 + 3 * x, 50 + 2 * y, np.full_like(x, 90)], -1).astype(np.uint8)


def outside(frame: np.ndarray, border: str) -> np.ndarray:
    """The 6 columns left of the shifted frame, as the ``border`` fills them."""
    if border == "black":
        return np.zeros_like(frame[:, :6])
    if border == "edge":
        return np.repeat(frame[:, :1], 6, axis=1)
    return frame[:, 6:0:-1]  # about the edge pixel's centre: column -k is column k


@pytest.mark.parametrize("border", ["black", "edge", "mirror"])
def test_each_warp_fills_the_uncovered_strip_alike(border):
    frame = ramp()
    wanted = np.concatenate([outside(frame, border), frame[:, :-6]], axis=1)
    np.testing.assert_array_equal(warp_frame(frame, SHIFT, border), wanted)
    rows = np.linspace(-0.5, 39.5, 5)
    source = rolling_source(np.repeat(SHIFT[None], 5, 0), rows)
    assert np.abs(remap_from(frame, source, border=border).astype(int) - wanted).max() <= 1
    # the batched warps of CUDA, run on the CPU: the same pixels
    by_torch = warp_frames_torch(frame[None], SHIFT[None], "cpu", border=border)[0]
    assert np.abs(by_torch.astype(int) - wanted).max() <= 1
    coarse = coarse_map(source, frame.shape[:2])[None]
    by_grid = remap_frames_torch(frame[None], coarse, "cpu", border=border)[0]
    assert np.abs(by_grid.astype(int) - wanted).max() <= 1
    # I420: each plane alike, its black in the frame's range
    planar = from_rgb(frame)
    for warped in (
        warp_planes(planar, SHIFT, False, border),
        remap_planes(planar, source, False, border),
    ):
        y = i420.split(warped)[0]
        if border == "black":
            assert y[:, :5].max() == 16
        else:
            assert np.abs(y[:, :6].astype(int) - outside(i420.split(planar)[0], border)).max() <= 1


def test_an_uncropped_clip_keeps_no_black_band_with_its_edge_repeated(shaky, tmp_path):
    # --crop none showed the frame's moving edge as a black band, which jumps with the shake
    def darkest_share(border: str) -> float:
        out = tmp_path / f"{border}.mp4"
        stabilize_video(shaky, out, Settings(fov=70.0, crop="none", border=border))
        frames = np.stack(list(read_frames(out, info=probe(out))))
        return float((frames.max(axis=-1) < 8).mean())

    assert darkest_share("black") > 0.005 and darkest_share("edge") < 1e-4


def test_an_unknown_border_is_refused():
    with pytest.raises(ValueError, match="--border must be one of black, edge, mirror"):
        check_settings(Settings(border="blur"))
