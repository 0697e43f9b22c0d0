"""Re-export of :mod:`tcp_pendant.text_escape` (the escaping moved out of ``views`` so that
``calibrate.text`` and ``pendant`` can use it without loading viser)."""

from tcp_pendant.text_escape import *  # noqa: F401,F403
from tcp_pendant.text_escape import __all__  # noqa: F401
