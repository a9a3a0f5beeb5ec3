"""Signal temporal logic: rtamt's discrete-time syntax (``syntax``), a batched numpy monitor
(``monitor``) and a scenario's requirements judged on a run's samples (``requirement``).

Plain numpy and text, below every other layer: the scenario loader refuses a bad formula
with it, the engine judges runs with it, and nothing here knows a world or a run.
"""
