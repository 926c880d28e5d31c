"""Each command's parser: ``wmr_mj.cli.parsers.<name>`` holds ``HELP`` (its line in ``wmr-mj --help``) and
``register(subparsers)``, which adds its parser (its description, its epilog) and its options: the command's rows
of the options table (:func:`wmr_mj.cli.command_options.add_command_options`). A module here imports argparse and
the light modules of the CLI (the options table, :mod:`wmr_mj.cli.options`) and never a command's implementation,
so that ``wmr-mj --help`` and a bad option answer without importing the simulation (tests/test_cli_help.py). The
implementation of command ``<name>`` is :mod:`wmr_mj.cli.<name>` (its ``run(args)``), imported by
:func:`wmr_mj.cli.app.main` once the command line is parsed."""
