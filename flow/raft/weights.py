"""Finding and loading published RAFT checkpoints.

Accepted as published, the format and variant detected from the keys:

* princeton-vl/RAFT: ``raft-small.pth``, ``raft-things.pth`` (and the other large
  checkpoints); keys prefixed ``module.`` (saved from DataParallel), or not.
* torchvision: the ``raft_small`` / ``raft_large`` state dicts
  (``feature_encoder.*``, ``context_encoder.*``, ``update_block.*``, ``mask_predictor.*``).

Weights are looked for in this order: an explicit path, the environment variable
``STABILIZE_RAFT_WEIGHTS``, then the user cache directory. Nothing is downloaded.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import torch

ENV_VAR = "STABILIZE_RAFT_WEIGHTS"
CACHE_NAMES = {  # looked for in this order in the cache directory
    "small": ("raft-small.pth", "raft_small_C_T_V1-ad48884c.pth"),
    "large": ("raft-things.pth", "raft_large_C_T_V1-22a6c225.pth"),
}
SOURCES = (
    "the official checkpoints are in models.zip of https://github.com/princeton-vl/RAFT "
    "(raft-small.pth, raft-things.pth); torchvision's raft_small/raft_large weights also load"
)


class WeightsNotFound(FileNotFoundError):
    """No RAFT checkpoint was found; the message says where to put one."""


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "hough-stabilize"


def find_weights(variant: str, path: str | os.PathLike | None = None) -> Path:
    """The checkpoint to load for ``variant``, or :class:`WeightsNotFound`."""
    if path is not None:
        found = Path(path).expanduser()
        if not found.is_file():
            raise WeightsNotFound(f"RAFT weights not found at {found}")
        return found
    if os.environ.get(ENV_VAR):
        found = Path(os.environ[ENV_VAR]).expanduser()
        if not found.is_file():
            raise WeightsNotFound(f"{ENV_VAR}={found} does not name a file")
        return found
    for name in CACHE_NAMES[variant]:
        if (cache_dir() / name).is_file():
            return cache_dir() / name
    raise WeightsNotFound(
        f"no RAFT-{variant} weights: put {CACHE_NAMES[variant][0]} in {cache_dir()}, "
        f"set {ENV_VAR}, or pass --raft-weights; {SOURCES}"
    )


def load_checkpoint(path: str | os.PathLike) -> dict[str, torch.Tensor]:
    """A state dict from a ``.pth`` file (legacy or zip format), tensors only."""
    try:
        state = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as err:  # torch raises many types for a bad file
        raise ValueError(f"{path} is not a readable PyTorch checkpoint ({err})") from None
    if isinstance(state, dict) and "state_dict" in state:
        state = state["state_dict"]
    if not isinstance(state, dict) or not state:
        raise ValueError(f"{path} holds no state dict")
    return state


def detect(state: dict[str, torch.Tensor]) -> tuple[str, str]:
    """(format, variant): format is ``official`` or ``torchvision``; variant ``small``/``large``."""
    keys = [k.removeprefix("module.") for k in state]
    if any(k.startswith("fnet.") for k in keys):
        large = any(k.startswith("update_block.mask.") for k in keys)
        return "official", "large" if large else "small"
    if any(k.startswith("feature_encoder.") for k in keys):
        large = any(k.startswith("mask_predictor.") for k in keys)
        return "torchvision", "large" if large else "small"
    raise ValueError("not a RAFT checkpoint: expected fnet.* or feature_encoder.* keys")


def to_official(state: dict[str, torch.Tensor]) -> tuple[dict[str, torch.Tensor], str]:
    """Convert any accepted checkpoint to official key names; return it and the variant."""
    fmt, variant = detect(state)
    if fmt == "official":
        return {k.removeprefix("module."): v for k, v in state.items()}, variant
    out: dict[str, torch.Tensor] = {}
    for key, value in state.items():
        for name in torchvision_to_official(key, variant):
            out[name] = value
    return out, variant


_RENAMES = [
    (r"^feature_encoder\.", "fnet."),
    (r"^context_encoder\.", "cnet."),
    (r"^(fnet|cnet)\.convnormrelu\.0\.", r"\1.conv1."),
    (r"^(fnet|cnet)\.convnormrelu\.1\.", r"\1.norm1."),
    (r"^(fnet|cnet)\.conv\.", r"\1.conv2."),
    (r"\.convnormrelu(\d)\.0\.", r".conv\1."),
    (r"\.convnormrelu(\d)\.1\.", r".norm\1."),
    (r"^update_block\.motion_encoder\.convcorr(\d)\.0\.", r"update_block.encoder.convc\1."),
    (r"^update_block\.motion_encoder\.convflow(\d)\.0\.", r"update_block.encoder.convf\1."),
    (r"^update_block\.motion_encoder\.conv\.0\.", "update_block.encoder.conv."),
    (r"^mask_predictor\.convrelu\.0\.", "update_block.mask.0."),
    (r"^mask_predictor\.conv\.", "update_block.mask.2."),
]


def torchvision_to_official(key: str, variant: str) -> list[str]:
    """Official name(s) of a torchvision key (a striding block's shortcut norm has two)."""
    for pattern, repl in _RENAMES:
        key = re.sub(pattern, repl, key)
    gru = re.match(r"^update_block\.recurrent_block\.convgru(\d)\.(conv[zrq])\.(.*)$", key)
    if gru:
        suffix = "" if variant == "small" else gru.group(1)
        key = f"update_block.gru.{gru.group(2)}{suffix}.{gru.group(3)}"
    shortcut = re.match(r"^(.*\.layer\d\.\d)\.downsample\.1\.(.*)$", key)
    if shortcut:
        norm = "norm4" if variant == "small" else "norm3"
        return [key, f"{shortcut.group(1)}.{norm}.{shortcut.group(2)}"]
    return [key]
