"""L4: one scenario into a run directory; expectations."""
