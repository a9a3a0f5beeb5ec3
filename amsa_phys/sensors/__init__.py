"""L2: sensors. They read Data like any consumer and never import the physics."""
