"""RAFT optical flow, re-implemented in torch; loads the published checkpoints."""

from flow.raft.backend import RaftFlow
from flow.raft.network import RAFT
from flow.raft.weights import WeightsNotFound, find_weights

__all__ = ["RAFT", "RaftFlow", "WeightsNotFound", "find_weights"]
