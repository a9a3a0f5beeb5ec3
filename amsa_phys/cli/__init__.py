"""L5: the command line. One module per subcommand with ``add_args`` and ``run``."""
