"""Optical-flow backends behind one small interface.

>>> import flow
>>> backend = flow.get("dis")                    # the default: fast on any CPU
>>> f = backend(frame0, frame1)                  # doctest: +SKIP
>>> flows = backend.many(frames)                 # doctest: +SKIP

Backends compute flow at exactly the size of the frames they are given; choose the
working size with :func:`flow.working_size` (about 480 px on the long side).
"""

from __future__ import annotations

import os
from collections.abc import Callable

from flow.base import FlowBackend
from flow.dis import DISFlow
from flow.resize import WorkingSize, working_size


def _raft(variant: str) -> Callable[..., FlowBackend]:
    def make(**options) -> FlowBackend:
        from flow.raft import RaftFlow  # torch is imported only when RAFT is asked for

        return RaftFlow(variant, **options)

    return make


# The learned backends: a name → its RAFT variant, whose checkpoint it loads
RAFT_VARIANTS = {"raft": "small", "raft-large": "large"}
# The registry: a backend's name → its factory. Adding one is one line here.
BACKENDS: dict[str, Callable[..., FlowBackend]] = {
    "dis": DISFlow,
    **{name: _raft(variant) for name, variant in RAFT_VARIANTS.items()},
}


def get(name: str = "dis", **options) -> FlowBackend:
    """A flow backend by name: ``"dis"`` (default), ``"raft"`` or ``"raft-large"``.

    Options go to the backend: ``preset`` for DIS; ``weights``, ``iters``, ``device``
    and ``batch_size`` for RAFT (:class:`flow.raft.RaftFlow`).
    """
    if name not in BACKENDS:
        raise ValueError(f"unknown flow backend {name!r}; choose from {', '.join(BACKENDS)}")
    return BACKENDS[name](**options)


def check_weights(name: str, weights: str | os.PathLike | None = None) -> None:
    """``FileNotFoundError`` where backend ``name`` would find no checkpoint, loading
    no model: a batch checks once, before its workers start (a CUDA context made before
    they fork would not work in them)."""
    if name in RAFT_VARIANTS:
        from flow.raft.weights import find_weights

        find_weights(RAFT_VARIANTS[name], weights)


__all__ = [
    "BACKENDS",
    "RAFT_VARIANTS",
    "DISFlow",
    "FlowBackend",
    "WorkingSize",
    "check_weights",
    "get",
    "working_size",
]
