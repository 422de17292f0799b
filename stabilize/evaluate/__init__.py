"""Judging a result: the literature's quality metrics, the run's report, and the visual
estimate against a gyroscope."""

from stabilize.evaluate.metrics import ClipMetrics, evaluate, evaluate_against, evaluate_pair

__all__ = ["ClipMetrics", "evaluate", "evaluate_against", "evaluate_pair"]
