"""Judging a result: the literature's quality metrics, the run's report, and the visual
estimate against a gyroscope."""

from stabilize.evaluate.metrics import (
    ClipMetrics,
    ShakeSpread,
    evaluate,
    evaluate_against,
    evaluate_pair,
    shake_spread,
)

__all__ = [
    "ClipMetrics",
    "ShakeSpread",
    "evaluate",
    "evaluate_against",
    "evaluate_pair",
    "shake_spread",
]
