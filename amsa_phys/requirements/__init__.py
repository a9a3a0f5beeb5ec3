"""Requirements in signal temporal logic: parsing, a batched numpy monitor, and objectives.

``objective`` turns a run's metrics and an objective name (a metric, or
``robustness.NAME``) into a value and its sense: the one place ``falsify``, ``tune`` and
``adapt`` learn which way is better.
"""
