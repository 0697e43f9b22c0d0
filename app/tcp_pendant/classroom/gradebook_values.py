"""The values the gradebook stores, checked before any SQL runs: labels, finite numbers, poses,
vectors, JSON, ids and times.

Units: poses in metres (``T_world_flange_m``), joints and angles in degrees, distances and
errors in mm, durations in seconds; times are UTC ISO 8601 with milliseconds
(``2025-01-31T09:15:02.125+00:00``, :func:`utc_now`).

Every check raises :class:`~tcp_pendant.classroom.gradebook_store.GradebookError` naming the
value and what it must be.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from datetime import datetime, timezone
from typing import Literal, overload

import numpy as np

from tcp_pendant.classroom.gradebook_store import GradebookError

__all__ = [
    "MAX_TEXT",
    "duration_s",
    "finite",
    "json_value",
    "label",
    "matrix4",
    "truth_json",
    "utc_now",
    "vector",
    "whole_id",
]

MAX_TEXT = 200          # method, tool key, exercise id, mode, crash note: short labels


def utc_now() -> str:
    """Now, UTC ISO 8601 with milliseconds."""
    return datetime.now(timezone.utc).isoformat(timespec="milliseconds")


def duration_s(start: str, end: str) -> float:
    """Seconds from ``start`` to ``end`` (ISO 8601 times)."""
    return (datetime.fromisoformat(end) - datetime.fromisoformat(start)).total_seconds()


@overload
def label(value: object, what: str, *, optional: Literal[False] = False) -> str: ...
@overload
def label(value: object, what: str, *, optional: bool) -> str | None: ...
def label(value: object, what: str, *, optional: bool = False) -> str | None:
    """``value`` if it is a non-empty printable text of at most :data:`MAX_TEXT` characters
    (``optional``: None passes too)."""
    if value is None and optional:
        return None
    if not isinstance(value, str) or not value.strip():
        raise GradebookError(f"{what} must be a non-empty text, got {value!r}.")
    if len(value) > MAX_TEXT or not value.isprintable():
        raise GradebookError(f"{what} must be at most {MAX_TEXT} printable characters, got {value!r:.80}.")
    return value


def finite(value: object, what: str, *, optional: bool = False) -> float | None:
    """``value`` as a finite float (``optional``: None passes too); a bool is not a number."""
    if value is None and optional:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise GradebookError(f"{what} must be a number, got {value!r:.80}.")
    out = float(value)
    if not math.isfinite(out):
        raise GradebookError(f"{what} must be finite, got {out!r}.")
    return out


def matrix4(value: object, what: str) -> list[list[float]]:
    """``value`` as a finite 4x4 matrix (nested lists)."""
    try:
        T = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise GradebookError(f"{what} must be a 4x4 matrix of numbers: {exc}.") from None
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise GradebookError(f"{what} must be a finite 4x4 matrix, got shape {T.shape}.")
    return T.tolist()


def vector(value: object, what: str, n: int | None = None) -> list[float]:
    """``value`` as a list of finite numbers (``n`` of them when given)."""
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise GradebookError(f"{what} must be numbers: {exc}.") from None
    if v.ndim != 1 or (n is not None and v.shape[0] != n) or not np.all(np.isfinite(v)):
        want = f"{n} finite numbers" if n is not None else "a list of finite numbers"
        raise GradebookError(f"{what} must be {want}, got shape {v.shape}.")
    return v.tolist()


def json_value(value: object, what: str, depth: int = 0) -> object:
    """A copy of ``value`` made of JSON types only (finite numbers, str keys), at most 8 deep."""
    if depth > 8:
        raise GradebookError(f"{what} nests more than 8 levels.")
    if isinstance(value, Mapping):
        out: dict[str, object] = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise GradebookError(f"{what} keys must be text, got {k!r:.40}.")
            out[k] = json_value(v, f"{what}[{k!r}]", depth + 1)
        return out
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [json_value(v, f"{what}[{i}]", depth + 1) for i, v in enumerate(value)]
    if value is None or isinstance(value, (bool, str)):
        return value
    return finite(value, what)


def truth_json(truth: object) -> str:
    """The true TOOL frame as stored (``calibrations.truth_json``): a non-empty JSON-able dict
    as given, or ``{"T_flange_tool_true_m": 4x4}`` for a matrix (metres)."""
    if isinstance(truth, Mapping):
        if not truth:
            raise GradebookError("the truth must not be empty: give T_flange_tool_true_m (4x4, m) "
                                 "or a dict describing the true TOOL frame.")
        return json.dumps(json_value(truth, "truth"), sort_keys=True)
    return json.dumps({"T_flange_tool_true_m": matrix4(truth, "T_flange_tool_true_m")})


def whole_id(value: object, what: str) -> int:
    """``value`` as an id (a whole number; a bool is not one)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise GradebookError(f"{what} must be a whole number (an id this gradebook returned), got {value!r:.40}.")
    return int(value)
