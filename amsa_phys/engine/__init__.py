"""L1: how a system *runs* — exact time, ordering, timeline, trace and metrics."""
