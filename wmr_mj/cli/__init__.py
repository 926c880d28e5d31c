"""The ``wmr-mj`` command line: one thin module per command."""
