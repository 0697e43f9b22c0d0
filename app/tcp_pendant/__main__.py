"""``python -m tcp_pendant``: same as the ``tcp-pendant`` command."""

import sys

from tcp_pendant.serve.cli import main

sys.exit(main())
