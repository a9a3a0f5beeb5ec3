"""L2: rigid-body physics. The only package that imports pymunk."""
