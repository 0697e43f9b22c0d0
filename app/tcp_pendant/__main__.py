"""``python -m tcp_pendant``: same as the ``tcp-pendant`` command."""

import sys

from tcp_pendant.cli import main

sys.exit(main())
