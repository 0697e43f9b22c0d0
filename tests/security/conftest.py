"""Setup of the security tests (their pendants, servers and browsers are the fixtures of
``support.fixtures``)."""

from __future__ import annotations

import os

# a fast path into viser's private API that falls back raises (views.viser_adapter)
os.environ.setdefault("TCP_PENDANT_STRICT_VISER", "1")
