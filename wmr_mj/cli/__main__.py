"""``python -m wmr_mj.cli``: the ``wmr-mj`` command."""

import sys

from wmr_mj.cli.app import main

sys.exit(main())
