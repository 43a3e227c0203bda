"""The subcommands of ``facetraj``: each module has ``register(subparsers)``, which adds its
parsers and sets ``func`` to the function that runs the command (returning the exit status)."""
