"""``python -m tcpcal``: the same as the ``tcpcal`` console script (see docs/cli.md)."""

import sys

from tcpcal.cli import main

sys.exit(main())
