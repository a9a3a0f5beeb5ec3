"""L3: matplotlib figures (Agg backend) from a run's trace and metrics."""
