"""Kept for importers: the metrics moved to ``model/metrics.py`` (names and computation in
one module, below the engine so the scenario loader can name them)."""

from ..model.metrics import METRICS, block_metrics, default_dwell

__all__ = ["METRICS", "block_metrics", "default_dwell"]
