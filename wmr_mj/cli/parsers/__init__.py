"""Each command's parser: ``wmr_mj.cli.parsers.<name>`` holds ``HELP`` (its line in ``wmr-mj --help``) and
``register(subparsers)``, which adds its parser and its options, and the option adders it shares with other
commands. A module here imports argparse and the light modules of the CLI (:mod:`wmr_mj.cli.options`, the table
of run options :mod:`wmr_mj.cli.run_options`, :mod:`wmr_mj.params`) and never a command's implementation, so that
``wmr-mj --help`` and a bad option answer without importing the simulation (tests/test_cli_help.py). The
implementation of command ``<name>`` is :mod:`wmr_mj.cli.<name>` (its ``run(args)``), imported by
:func:`wmr_mj.cli.app.main` once the command line is parsed."""
