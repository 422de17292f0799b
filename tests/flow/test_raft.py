"""RAFT re-implementation: exact against the official model, and checkpoint handling."""

import json
import re

import cv2
import numpy as np
import pytest
import torch

import flow
from flow.raft import RAFT, RaftFlow, WeightsNotFound, find_weights
from flow.raft.weights import detect, load_checkpoint, to_official, torchvision_to_official
from tests.flow.conftest import shifted_pair


def read_rgb(path) -> np.ndarray:
    return cv2.imread(str(path), cv2.IMREAD_COLOR)[..., ::-1].copy()


@pytest.fixture(scope="module")
def raft(raft_weights) -> RaftFlow:
    return RaftFlow("small", weights=raft_weights, device="cpu")


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
@pytest.mark.parametrize("iters", [12, 20])
def test_matches_the_official_reference_flow(shared, raft, case, iters):
    folder = shared / "raft" / case
    frame0, frame1 = read_rgb(folder / "frame0.png"), read_rgb(folder / "frame1.png")
    reference = np.load(folder / f"flow_iters{iters}.npy")
    raft.iters = iters
    try:
        for result in (raft(frame0, frame1), next(raft.many([frame0, frame1]))):
            diff = np.abs(result - reference)
            assert diff.max() < 1e-3 and diff.mean() < 5e-5, (diff.max(), diff.mean())
    finally:
        raft.iters = 12


def test_low_resolution_flow_matches_too(shared, raft):
    folder = shared / "raft" / "case2"
    params = json.loads((folder / "params.json").read_text())
    assert params["model"] == "raft-small"
    images = [
        torch.from_numpy(read_rgb(folder / f"frame{k}.png")).permute(2, 0, 1)[None].float()
        for k in (0, 1)
    ]
    with torch.inference_mode():
        low, _ = raft.model(*images, iters=20)
    reference = np.load(folder / "flow_lowres_iters20.npy")
    assert np.abs(low[0].permute(1, 2, 0).numpy() - reference).max() < 1e-4


def test_direction_channel_order_and_odd_sizes(raft):
    # Content moves 3 px right and 1 px up: u = +3, v = -1 (CONVENTIONS.md).
    frame0, frame1 = shifted_pair(141, 203, 3.0, -1.0)
    f = raft(frame0, frame1)
    assert f.shape == (141, 203, 2) and f.dtype == np.float32
    np.testing.assert_allclose(np.median(f[15:-15, 15:-15].reshape(-1, 2), 0), [3, -1], atol=0.2)
    grey = raft(frame0.mean(2).astype(np.uint8), frame1.mean(2).astype(np.uint8))
    assert grey.shape == f.shape
    assert np.median(grey[15:-15, 15:-15, 0]) == pytest.approx(3.0, abs=0.3)


def test_frames_below_the_network_minimum_are_padded(raft):
    frame0, frame1 = shifted_pair(77, 101, 3.0, -1.0)
    f = raft(frame0, frame1)
    assert f.shape == (77, 101, 2) and np.isfinite(f).all()
    assert np.median(f[15:-15, 15:-15, 0]) == pytest.approx(3.0, abs=0.5)


def test_many_encodes_each_frame_once_and_matches_pairs(raft):
    frames = [shifted_pair(64, 96, k, 0)[1] for k in range(4)]
    calls = {"n": 0}
    original = raft.model.features

    def counting(images):
        calls["n"] += images.shape[0]
        return original(images)

    raft.model.features = counting
    try:
        many = list(raft.many(iter(frames)))
    finally:
        del raft.model.features
    assert calls["n"] == len(frames)
    for k, f in enumerate(many):
        np.testing.assert_allclose(f, raft(frames[k], frames[k + 1]), atol=1e-3)


def test_batched_many_matches_unbatched(raft_weights):
    frames = [shifted_pair(64, 96, k, k / 2)[1] for k in range(5)]
    one = list(RaftFlow("small", weights=raft_weights, device="cpu").many(frames))
    four = list(RaftFlow("small", weights=raft_weights, device="cpu", batch_size=3).many(frames))
    assert len(one) == len(four) == 4
    for a, b in zip(one, four, strict=True):
        np.testing.assert_allclose(a, b, atol=1e-3)


def test_mismatched_sizes_raise(raft):
    with pytest.raises(ValueError, match="sizes differ"):
        raft(np.zeros((64, 64, 3), np.uint8), np.zeros((64, 72, 3), np.uint8))


def test_flow_get_finds_weights_from_the_environment(monkeypatch, raft_weights):
    monkeypatch.setenv("STABILIZE_RAFT_WEIGHTS", str(raft_weights))
    assert flow.get("raft", device="cpu").name == "raft"


def test_weight_search_order(monkeypatch, tmp_path, raft_weights):
    monkeypatch.delenv("STABILIZE_RAFT_WEIGHTS", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    with pytest.raises(WeightsNotFound, match=r"raft-small\.pth") as err:
        find_weights("small")
    assert "princeton-vl/RAFT" in str(err.value) and str(tmp_path) in str(err.value)
    cached = tmp_path / "hough-stabilize" / "raft-small.pth"
    cached.parent.mkdir()
    cached.write_bytes(raft_weights.read_bytes())
    assert find_weights("small") == cached
    monkeypatch.setenv("STABILIZE_RAFT_WEIGHTS", str(raft_weights))
    assert find_weights("small") == raft_weights  # the environment beats the cache
    assert find_weights("small", cached) == cached  # an explicit path beats both
    with pytest.raises(WeightsNotFound):
        find_weights("small", tmp_path / "missing.pth")


def test_a_bad_checkpoint_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.pth"
    bad.write_text("not a checkpoint")
    with pytest.raises(ValueError, match="not a readable PyTorch checkpoint"):
        RaftFlow("small", weights=bad)


def test_official_checkpoint_detection(raft_weights):
    state = load_checkpoint(raft_weights)
    assert all(k.startswith("module.") for k in state)
    assert detect(state) == ("official", "small")
    converted, variant = to_official(state)
    assert variant == "small" and "fnet.conv1.weight" in converted
    assert sum(v.numel() for v in converted.values()) == 990_162


def official_to_torchvision(key: str, variant: str) -> str | None:
    """The torchvision name of an official key, written from torchvision's raft.py.

    None for the striding blocks' second name of their shortcut norm, which
    torchvision keeps only as downsample.1.
    """
    alias = "norm4" if variant == "small" else "norm3"
    if re.search(rf"\.layer\d\.\d\.{alias}\.", key):
        return None
    rules = [
        (r"^fnet\.", "feature_encoder."),
        (r"^cnet\.", "context_encoder."),
        (r"_encoder\.conv1\.", "_encoder.convnormrelu.0."),
        (r"_encoder\.norm1\.", "_encoder.convnormrelu.1."),
        (r"_encoder\.conv2\.", "_encoder.conv."),
        (r"(\.layer\d\.\d)\.conv(\d)\.", r"\1.convnormrelu\2.0."),
        (r"(\.layer\d\.\d)\.norm(\d)\.", r"\1.convnormrelu\2.1."),
        (r"^update_block\.encoder\.convc(\d)\.", r"update_block.motion_encoder.convcorr\1.0."),
        (r"^update_block\.encoder\.convf(\d)\.", r"update_block.motion_encoder.convflow\1.0."),
        (r"^update_block\.encoder\.conv\.", "update_block.motion_encoder.conv.0."),
        (r"^update_block\.gru\.conv([zrq])\.", r"update_block.recurrent_block.convgru1.conv\1."),
        (
            r"^update_block\.gru\.conv([zrq])(\d)\.",
            r"update_block.recurrent_block.convgru\2.conv\1.",
        ),
        (r"^update_block\.mask\.0\.", "mask_predictor.convrelu.0."),
        (r"^update_block\.mask\.2\.", "mask_predictor.conv."),
    ]
    for pattern, repl in rules:
        key = re.sub(pattern, repl, key)
    return key


TORCHVISION_NAMES = [  # (torchvision key, variant, official keys), names from torchvision
    ("feature_encoder.convnormrelu.0.weight", "small", ["fnet.conv1.weight"]),
    ("context_encoder.conv.bias", "small", ["cnet.conv2.bias"]),
    ("feature_encoder.layer2.0.convnormrelu3.0.weight", "small", ["fnet.layer2.0.conv3.weight"]),
    (
        "context_encoder.layer3.0.downsample.1.running_mean",
        "large",
        ["cnet.layer3.0.downsample.1.running_mean", "cnet.layer3.0.norm3.running_mean"],
    ),
    (
        "update_block.motion_encoder.convcorr2.0.weight",
        "large",
        ["update_block.encoder.convc2.weight"],
    ),
    ("update_block.recurrent_block.convgru2.convq.bias", "large", ["update_block.gru.convq2.bias"]),
    (
        "update_block.recurrent_block.convgru1.convr.weight",
        "small",
        ["update_block.gru.convr.weight"],
    ),
    ("mask_predictor.conv.weight", "large", ["update_block.mask.2.weight"]),
]


@pytest.mark.parametrize(("name", "variant", "official"), TORCHVISION_NAMES)
def test_torchvision_names_map_to_official_ones(name, variant, official):
    assert torchvision_to_official(name, variant) == official


@pytest.mark.parametrize("variant", ["small", "large"])
def test_every_official_key_has_a_torchvision_round_trip(variant):
    # Build a torchvision-style dict from our model's official names, load it back.
    torch.manual_seed(0)
    model = RAFT(variant)
    for m in model.modules():
        if isinstance(m, torch.nn.BatchNorm2d):
            m.running_mean.uniform_(-0.1, 0.1)
    state = model.state_dict()
    tv = {}
    for key, value in state.items():
        name = official_to_torchvision(key, variant)
        if name is not None:
            tv[name] = value
    assert detect(tv) == ("torchvision", variant)
    converted, found = to_official(tv)
    assert found == variant
    fresh = RAFT(variant)
    fresh.load_state_dict(converted, strict=True)
    for key, value in state.items():
        assert torch.equal(fresh.state_dict()[key], value), key


def test_large_model_runs_and_has_the_official_layout():
    model = RAFT("large").eval()
    keys = set(model.state_dict())
    for key in (
        "fnet.layer2.0.downsample.0.weight",
        "cnet.norm1.running_var",
        "cnet.layer2.0.norm3.weight",
        "update_block.gru.convz1.weight",
        "update_block.encoder.convc2.weight",
        "update_block.mask.2.bias",
    ):
        assert key in keys, key
    x = torch.rand(1, 3, 64, 96) * 255
    with torch.inference_mode():
        low, up = model(x, x, iters=2)
    assert low.shape == (1, 2, 8, 12) and up.shape == (1, 2, 64, 96)
