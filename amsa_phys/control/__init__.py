"""L2: actuators, controllers and monitors of the MDE challenge."""
