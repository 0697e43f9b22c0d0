"""Errors of the virtual controller (``tcp_pendant.controller``)."""

from __future__ import annotations

__all__ = ["ControllerError"]


class ControllerError(ValueError):
    """Base of every error the virtual controller raises.

    Raised for bad input (a URDF that cannot be loaded, an unknown link, joint angles outside the
    limits, a malformed pose); the message names the problem and what to do. A motion that
    cannot be carried out (joint limit, singularity, unreachable target) is *not* an error: it
    returns a ``JogResult`` with ``ok=False`` and says why.
    """
