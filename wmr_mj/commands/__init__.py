"""Subcommands of the ``wmr-mj`` CLI, one module each (see ``wmr_mj.cli``)."""
