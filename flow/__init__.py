"""Optical-flow backends behind one small interface.

>>> import flow
>>> backend = flow.get("dis")                    # the default: fast on any CPU
>>> f = backend(frame0, frame1)                  # doctest: +SKIP
>>> flows = backend.many(frames)                 # doctest: +SKIP

Backends compute flow at exactly the size of the frames they are given; choose the
working size with :func:`flow.working_size` (about 480 px on the long side).
"""

from __future__ import annotations

from collections.abc import Callable

from flow.base import FlowBackend
from flow.dis import DISFlow
from flow.resize import WorkingSize, working_size


def _raft(variant: str) -> Callable[..., FlowBackend]:
    def make(**options) -> FlowBackend:
        from flow.raft import RaftFlow  # torch is imported only when RAFT is asked for

        return RaftFlow(variant, **options)

    return make


# The registry: a backend's name → its factory. Adding one is one line here.
BACKENDS: dict[str, Callable[..., FlowBackend]] = {
    "dis": DISFlow,
    "raft": _raft("small"),
    "raft-large": _raft("large"),
}


def get(name: str = "dis", **options) -> FlowBackend:
    """A flow backend by name: ``"dis"`` (default), ``"raft"`` or ``"raft-large"``.

    Options go to the backend: ``preset`` for DIS; ``weights``, ``iters``, ``device``
    and ``batch_size`` for RAFT (:class:`flow.raft.RaftFlow`).
    """
    if name not in BACKENDS:
        raise ValueError(f"unknown flow backend {name!r}; choose from {', '.join(BACKENDS)}")
    return BACKENDS[name](**options)


__all__ = ["BACKENDS", "DISFlow", "FlowBackend", "WorkingSize", "get", "working_size"]
