"""The subcommands of ``evorbc-evolve``, one module each."""
