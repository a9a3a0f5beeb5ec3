"""Rules derived from exploration: a context sweep's best parameters, per context cell,
as ``adapt:`` conditions on the context estimators' outputs (``amsa-phys adapt``)."""
