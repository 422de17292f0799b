import cv2
import numpy as np
import pytest

import flow
from flow.resize import working_size
from tests.flow.conftest import shifted_pair


def test_get_names_the_backends():
    assert flow.get().name == "dis"
    assert flow.get("dis", preset="medium").preset == "medium"
    with pytest.raises(ValueError, match="unknown flow backend"):
        flow.get("lucas-kanade")


def test_dis_direction_and_channel_order():
    # Content moves 3 px right and 1 px down: u = +3, v = +1 (CONVENTIONS.md).
    frame0, frame1 = shifted_pair(120, 160, 3.0, 1.0)
    f = flow.get("dis")(frame0, frame1)
    assert f.shape == (120, 160, 2) and f.dtype == np.float32
    inner = f[20:-20, 20:-20]
    np.testing.assert_allclose(np.median(inner.reshape(-1, 2), axis=0), [3.0, 1.0], atol=0.1)


def test_dis_odd_size_grey_and_rgb():
    frame0, frame1 = shifted_pair(77, 101, -2.0, 0.5)
    backend = flow.get("dis")
    rgb = backend(frame0, frame1)
    grey = backend(frame0.mean(axis=2).astype(np.uint8), frame1.mean(axis=2).astype(np.uint8))
    assert rgb.shape == grey.shape == (77, 101, 2)
    assert np.median(rgb[..., 0]) == pytest.approx(-2.0, abs=0.15)


def test_dis_many_matches_pairs():
    # more pairs than are computed at once, each shift its own, so that a flow out of
    # order shows; OpenCV's threads are handed back after
    threads = cv2.getNumThreads()
    frames = [shifted_pair(64, 96, (k * k) % 5, k % 3)[1] for k in range(10)]
    backend = flow.get("dis")
    many = list(backend.many(iter(frames)))
    assert len(many) == 9
    for k, f in enumerate(many):
        np.testing.assert_array_equal(f, backend(frames[k], frames[k + 1]))
    assert cv2.getNumThreads() == threads


@pytest.mark.parametrize(
    "bad",
    [np.zeros((50, 60, 3), np.uint8), np.zeros((60, 50, 3), np.uint8)],
)
def test_mismatched_sizes_raise(bad):
    frame = np.zeros((60, 60, 3), np.uint8)
    with pytest.raises(ValueError, match="sizes differ"):
        flow.get("dis")(frame, bad)
    threads = cv2.getNumThreads()
    with pytest.raises(ValueError, match="sizes differ"):
        list(flow.get("dis").many([frame, frame, bad]))
    assert cv2.getNumThreads() == threads


def test_bad_frames_raise():
    with pytest.raises(ValueError, match="uint8"):
        flow.get("dis")(np.zeros((60, 60), np.float32), np.zeros((60, 60), np.float32))
    with pytest.raises(ValueError, match="RGB"):
        flow.get("dis")(np.zeros((60, 60, 4), np.uint8), np.zeros((60, 60, 4), np.uint8))


def test_working_size():
    ws = working_size((1080, 1920))
    assert ws.size == (270, 480) and ws.scale == (0.25, 0.25)
    assert working_size((1920, 1080)).size == (480, 270)  # portrait keeps its aspect
    assert working_size((200, 300)).size == (200, 300)  # never enlarges
    assert working_size((1080, 1920), multiple=8).size == (272, 480)
    assert working_size((1080, 1920), long_side=None).size == (1080, 1920)


def test_working_size_resize_and_back():
    ws = working_size((540, 960))
    frame0, frame1 = shifted_pair(540, 960, 8.0, -4.0)
    small = flow.get("dis")(ws.resize(frame0), ws.resize(frame1))
    assert small.shape == (270, 480, 2)
    assert np.median(small[..., 0]) == pytest.approx(4.0, abs=0.15)
    full = ws.flow_to_source(small)
    assert full.shape == (540, 960, 2)
    assert np.median(full[..., 0]) == pytest.approx(8.0, abs=0.3)
    with pytest.raises(ValueError):
        ws.resize(frame0[:-1])
