"""Tool data: a calibrated tool as a controller stores it.

A :class:`Tool` is the TOOL frame of one physical tool: its TCP ``t`` in FLANGE coordinates
(millimetres) and the orientation ``R_flange_tool`` as KUKA A, B, C angles in degrees
(``R = Rz(A) Ry(B) Rx(C)`` = ``Rotation.from_euler("ZYX", [A, B, C], degrees=True)``,
methods.md section 6), plus a name, an optional mass, free notes and how it was calibrated.

Names follow a controller's tool table: 1 to :data:`MAX_NAME_LENGTH` (24) printable characters
(no control or invisible character: Unicode categories C*, line and paragraph separators, and
spaces other than U+0020), no double quote (it ends a string literal in KRL and RAPID), no
leading or trailing spaces. Every Tool is checked when it is made, so this holds for names
typed in the pendant, given to ``tcpcal tools add``, set by ``ToolLibrary.rename`` or read from
a library file. What each controller format accepts beyond that: docs/cli.md, "Tool names".

Dictionary form (``Tool.to_dict`` / ``Tool.from_dict``; the tool library file stores exactly
this, so scripts may rely on these keys; they are a stable contract)::

    {
      "name": "gripper",                    # str
      "tcp_mm": [12.5, 0.0, 180.25],        # TCP in FLANGE, mm
      "abc_deg": [0.0, -90.0, 0.0],         # KUKA A, B, C of R_flange_tool, degrees
      "mass_kg": 2.5,                       # float > 0, or null when unknown
      "cog_mm": [0.0, 0.0, 80.0],           # optional: centre of gravity in FLANGE, mm
                                            #   (written only when known)
      "load_abc_deg": [0.0, 0.0, 0.0],      # optional: KUKA A, B, C of R_flange_load, the
                                            #   load's inertia axes at the centre of gravity,
                                            #   degrees (written only when known)
      "inertia_kgm2": [0.05, 0.05, 0.01],   # optional: moments of inertia about those axes
                                            #   through the centre of gravity, kg m^2
                                            #   (written only when known)
      "notes": "",                          # str
      "calibration": null | {
        "method": "xyz4-lstsq",             # e.g. "xyz4-lstsq", "reference", "three-point-1",
                                            #      "abc-world-6d", "numeric"
        "calibrated_at": "2024-05-01T12:00:00+00:00",   # ISO 8601, UTC
        "figures": {"mean_error_mm": 0.21, "max_error_mm": 0.35, "ci95_mm": 0.4}
      }
    }

``from_dict`` accepts missing optional keys (``abc_deg``, ``mass_kg``, ``cog_mm``,
``load_abc_deg``, ``inertia_kgm2``, ``notes``, ``calibration``) and rejects unknown keys, so a typo in a hand-edited file is reported instead
of silently dropped. Every number must be finite (JSON has no NaN). ``cog_mm``,
``load_abc_deg`` and ``inertia_kgm2`` are written only for a tool that has them, so the file of
a tool without them is the same as before those keys existed. A load a controller file does not
give stays unset (``null``/absent), never zero (docs/formats.md "Tool loads").
"""

from __future__ import annotations

import math
import types
import unicodedata
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.errors import InvalidInputError
from tcpcal.validation import as_rotation

__all__ = [
    "MAX_NAME_LENGTH",
    "Calibration",
    "Tool",
    "abc_deg_from_rotation",
    "rotation_from_abc_deg",
]

MAX_NAME_LENGTH: int = 24
"""Longest tool name, as on a KUKA controller (``TOOL_NAME[n, 24]``)."""

_TOOL_KEYS = ("name", "tcp_mm", "abc_deg", "mass_kg", "cog_mm", "load_abc_deg", "inertia_kgm2",
              "notes", "calibration")
_CALIBRATION_KEYS = ("method", "calibrated_at", "figures")


def rotation_from_abc_deg(abc_deg: Any) -> np.ndarray:
    """KUKA A, B, C (degrees) to a rotation matrix: ``R = Rz(A) Ry(B) Rx(C)`` (methods.md 6)."""
    return Rotation.from_euler("ZYX", np.asarray(abc_deg, dtype=float), degrees=True).as_matrix()


def abc_deg_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """Rotation matrix to KUKA A, B, C in degrees (inverse of :func:`rotation_from_abc_deg`).

    Uses ``Rotation.as_euler("ZYX")``. Within about 1e-7 rad of gimbal lock (B = +-90 deg)
    scipy sets C = 0 and the angles then reproduce the rotation only to ~1e-7; in that case
    (reconstruction error above 1e-12) the angles are recomputed by the two-step method:
    ``A = atan2(R10, R00)``, ``B = atan2(-R20, hypot(R00, R10))``, and C from the residual
    rotation ``(Rz(A) Ry(B))^T R = Rx(C)`` (composed with scipy), which absorbs the
    ill-conditioning of A so that ``Rz(A) Ry(B) Rx(C)`` reproduces ``R`` to machine precision.
    scipy's gimbal-lock warning is silenced. The angles are rounded to 12 decimals (changes the
    rotation by < 1e-14 rad) so that e.g. -90 deg does not read -89.99999999999999.
    """
    R = np.asarray(rotation, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        abc = Rotation.from_matrix(R).as_euler("ZYX", degrees=True)
    R_input = Rotation.from_matrix(R).as_matrix()  # the rotation scipy sees (orthonormalised)
    if np.abs(rotation_from_abc_deg(abc) - R_input).max() > 1e-12:
        a = math.atan2(R_input[1, 0], R_input[0, 0])
        b = math.atan2(-R_input[2, 0], math.hypot(R_input[0, 0], R_input[1, 0]))
        residual = (
            Rotation.from_euler("ZY", [a, b]).inv() * Rotation.from_matrix(R_input)
        ).as_matrix()
        c = math.atan2(residual[2, 1], residual[1, 1])
        two_step = np.degrees([a, b, c])
        err_two = np.abs(rotation_from_abc_deg(two_step) - R_input).max()
        if err_two < np.abs(rotation_from_abc_deg(abc) - R_input).max():
            abc = two_step
    return np.round(abc, 12) + 0.0  # + 0.0 turns -0.0 into 0.0


def _finite_float(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidInputError(f"{what} must be a number, got {value!r}.")
    out = float(value)
    if not math.isfinite(out):
        raise InvalidInputError(f"{what} must be a finite number, got {out!r}.")
    return out


def _triple(value: Any, what: str) -> tuple[float, float, float]:
    if isinstance(value, (str, bytes)) or not hasattr(value, "__len__") or len(value) != 3:
        raise InvalidInputError(f"{what} must be 3 numbers (x, y, z or A, B, C), got {value!r}.")
    a, b, c = (_finite_float(v, f"{what}[{i}]") for i, v in enumerate(value))
    return (a, b, c)


def _check_name(name: Any) -> str:
    if not isinstance(name, str):
        raise InvalidInputError(f"tool name must be a string, got {name!r}.")
    if not name.strip():
        raise InvalidInputError("tool name is empty; give the tool a name (1 to 24 characters).")
    if len(name) > MAX_NAME_LENGTH:
        raise InvalidInputError(
            f"tool name {name!r} has {len(name)} characters; a controller accepts at most "
            f"{MAX_NAME_LENGTH}: shorten it."
        )
    if not name.isprintable():  # Unicode categories C* and separators other than the space
        bad = next(ch for ch in name if not ch.isprintable())
        what = unicodedata.name(bad, unicodedata.category(bad))
        raise InvalidInputError(
            f"tool name {name!r} contains a control character, U+{ord(bad):04X} ({what}); a "
            "controller cannot show it: use printable characters only."
        )
    if '"' in name:
        raise InvalidInputError(
            f'tool name {name!r} contains a double quote ("), which ends a string on the '
            "controller; remove it."
        )
    if name != name.strip():
        raise InvalidInputError(
            f"tool name {name!r} starts or ends with a space; remove the surrounding spaces."
        )
    return name


def _utc_now_iso() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


@dataclass(frozen=True)
class Calibration:
    """How and when a tool was calibrated.

    Attributes:
        method: calibration method, e.g. ``"xyz4-lstsq"``, ``"reference"``,
            ``"three-point-1"``, ``"abc-world-6d"``, ``"numeric"`` (typed in by hand).
        calibrated_at: ISO 8601 date-time with a UTC offset (e.g. ``"2024-05-01T12:00:00+00:00"``
            or ``...Z``); see :meth:`now`.
        figures: quality figures by name, finite floats, e.g. ``{"mean_error_mm": 0.2,
            "max_error_mm": 0.35, "ci95_mm": 0.4}`` (stored read-only).
    """

    method: str
    calibrated_at: str
    figures: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.method, str) or not self.method.strip():
            raise InvalidInputError(
                f"calibration method must be a non-empty string such as 'xyz4-lstsq', got "
                f"{self.method!r}."
            )
        if not isinstance(self.calibrated_at, str):
            raise InvalidInputError(
                f"calibrated_at must be an ISO 8601 string, got {self.calibrated_at!r}."
            )
        text = self.calibrated_at.strip()
        try:
            stamp = datetime.fromisoformat(text[:-1] + "+00:00" if text.endswith("Z") else text)
        except ValueError:
            raise InvalidInputError(
                f"calibrated_at {self.calibrated_at!r} is not an ISO 8601 date-time; write it "
                "like '2024-05-01T12:00:00+00:00' (UTC)."
            ) from None
        if stamp.tzinfo is None:
            raise InvalidInputError(
                f"calibrated_at {self.calibrated_at!r} has no time zone; add the UTC offset "
                "('+00:00' or 'Z')."
            )
        if not isinstance(self.figures, Mapping):
            raise InvalidInputError(
                f"calibration figures must be a mapping of name -> number, got {self.figures!r}."
            )
        figures: dict[str, float] = {}
        for key, value in self.figures.items():
            if not isinstance(key, str) or not key:
                raise InvalidInputError(
                    f"calibration figure names must be non-empty strings, got {key!r}."
                )
            figures[key] = _finite_float(value, f"calibration figure {key!r}")
        object.__setattr__(self, "figures", types.MappingProxyType(figures))

    def __hash__(self) -> int:
        return hash((self.method, self.calibrated_at, tuple(sorted(self.figures.items()))))

    @classmethod
    def now(cls, method: str, figures: Mapping[str, float] | None = None) -> Calibration:
        """A calibration stamped with the current UTC time (seconds resolution)."""
        return cls(method=method, calibrated_at=_utc_now_iso(), figures=dict(figures or {}))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with the keys ``method``, ``calibrated_at``, ``figures``."""
        return {
            "method": self.method,
            "calibrated_at": self.calibrated_at,
            "figures": dict(self.figures),
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Calibration:
        """Inverse of :meth:`to_dict`; raises InvalidInputError on missing or unknown keys."""
        if not isinstance(d, Mapping):
            raise InvalidInputError(f"calibration must be an object, got {d!r}.")
        unknown = sorted(set(d) - set(_CALIBRATION_KEYS))
        if unknown:
            raise InvalidInputError(
                f"calibration has unknown keys {unknown}; allowed: {list(_CALIBRATION_KEYS)}."
            )
        missing = [k for k in ("method", "calibrated_at") if k not in d]
        if missing:
            raise InvalidInputError(f"calibration lacks the keys {missing}.")
        return cls(
            method=d["method"], calibrated_at=d["calibrated_at"], figures=d.get("figures", {})
        )


@dataclass(frozen=True)
class Tool:
    """A calibrated tool: TOOL frame relative to FLANGE, in mm and KUKA degrees.

    ``T_flange_tool = [[R, t], [0, 1]]`` with ``t = tcp_mm`` and
    ``R = Rz(A) Ry(B) Rx(C)`` from ``abc_deg`` (methods.md sections 1 and 6): the columns of
    ``R`` are the tool X, Y, Z axes in FLANGE coordinates. Tool X is the working direction.

    Attributes:
        name: 1..24 printable characters, no double quote, no surrounding spaces.
        tcp_mm: TCP in FLANGE coordinates, mm (3 finite floats).
        abc_deg: KUKA A, B, C of ``R_flange_tool``, degrees (3 finite floats).
        mass_kg: tool mass in kg (> 0) or None when unknown.
        cog_mm: the tool's centre of gravity in FLANGE coordinates, mm (3 finite floats), or
            None when unknown (a controller's load data: Yaskawa ``TOOL.CND``, ABB ``tload``).
        load_abc_deg: KUKA A, B, C (deg) of ``R_flange_load``, the axes of the load's moments of
            inertia at the centre of gravity (ABB ``tload.aom``, KUKA ``LOAD_DATA`` CM A, B, C),
            or None when unknown.
        inertia_kgm2: the load's moments of inertia about those axes through the centre of
            gravity, kg m^2 (each >= 0: ABB ``ix, iy, iz``, KUKA ``J``, Yaskawa ``Ix, Iy, Iz``),
            or None when unknown.
        notes: free text.
        calibration: how and when it was calibrated, or None (e.g. typed in).

    Raises:
        InvalidInputError: on any invalid field, naming it.
    """

    name: str
    tcp_mm: tuple[float, float, float]
    abc_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mass_kg: float | None = None
    notes: str = ""
    calibration: Calibration | None = None
    cog_mm: tuple[float, float, float] | None = None
    load_abc_deg: tuple[float, float, float] | None = None
    inertia_kgm2: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        _check_name(self.name)
        object.__setattr__(self, "tcp_mm", _triple(self.tcp_mm, "tcp_mm"))
        object.__setattr__(self, "abc_deg", _triple(self.abc_deg, "abc_deg"))
        if self.mass_kg is not None:
            mass = _finite_float(self.mass_kg, "mass_kg")
            if mass <= 0.0:
                raise InvalidInputError(
                    f"mass_kg must be positive (kg) or None when unknown, got {mass!r}."
                )
            object.__setattr__(self, "mass_kg", mass)
        if self.cog_mm is not None:
            object.__setattr__(self, "cog_mm", _triple(self.cog_mm, "cog_mm"))
        if self.load_abc_deg is not None:
            object.__setattr__(self, "load_abc_deg", _triple(self.load_abc_deg, "load_abc_deg"))
        if self.inertia_kgm2 is not None:
            inertia = _triple(self.inertia_kgm2, "inertia_kgm2")
            if min(inertia) < 0.0:
                raise InvalidInputError(
                    f"inertia_kgm2 must be 3 moments of inertia >= 0 (kg m^2), got {inertia!r}.")
            object.__setattr__(self, "inertia_kgm2", inertia)
        if not isinstance(self.notes, str):
            raise InvalidInputError(f"notes must be a string, got {self.notes!r}.")
        if self.calibration is not None and not isinstance(self.calibration, Calibration):
            raise InvalidInputError(
                f"calibration must be a Calibration or None, got {self.calibration!r}."
            )

    @property
    def rotation(self) -> np.ndarray:
        """``R_flange_tool`` (3, 3): ``Rotation.from_euler("ZYX", abc_deg, degrees=True)``."""
        return rotation_from_abc_deg(self.abc_deg)

    @property
    def T_flange_tool_mm(self) -> np.ndarray:
        """Homogeneous ``T_flange_tool`` (4, 4), translation in mm."""
        T = np.eye(4)
        T[:3, :3] = self.rotation
        T[:3, 3] = self.tcp_mm
        return T

    def load_fields(self) -> dict[str, Any]:
        """The tool's load as keyword arguments of :class:`Tool` (``mass_kg``, ``cog_mm``,
        ``load_abc_deg``, ``inertia_kgm2``): what a new calibration of the tool keeps."""
        return {"mass_kg": self.mass_kg, "cog_mm": self.cog_mm,
                "load_abc_deg": self.load_abc_deg, "inertia_kgm2": self.inertia_kgm2}

    @classmethod
    def from_rotation(
        cls, name: str, tcp_mm: Any, rotation: Any, **kw: Any
    ) -> Tool:
        """Build a tool from ``R_flange_tool`` (3x3 proper rotation) instead of A, B, C.

        Args:
            name: tool name.
            tcp_mm: TCP in FLANGE, mm.
            rotation: ``R_flange_tool``; checked with :func:`tcpcal.validation.as_rotation`
                (orthonormal within 1e-6, det +1).
            **kw: ``mass_kg``, ``cog_mm``, ``load_abc_deg``, ``inertia_kgm2``, ``notes``,
                ``calibration``.
        """
        R = as_rotation(rotation, name="rotation")
        abc = abc_deg_from_rotation(R)
        return cls(name=name, tcp_mm=tcp_mm,
                   abc_deg=(float(abc[0]), float(abc[1]), float(abc[2])), **kw)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with the stable keys documented in the module docstring."""
        out: dict[str, Any] = {
            "name": self.name,
            "tcp_mm": list(self.tcp_mm),
            "abc_deg": list(self.abc_deg),
            "mass_kg": self.mass_kg,
        }
        if self.cog_mm is not None:
            out["cog_mm"] = list(self.cog_mm)
        if self.load_abc_deg is not None:
            out["load_abc_deg"] = list(self.load_abc_deg)
        if self.inertia_kgm2 is not None:
            out["inertia_kgm2"] = list(self.inertia_kgm2)
        out["notes"] = self.notes
        out["calibration"] = None if self.calibration is None else self.calibration.to_dict()
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> Tool:
        """Inverse of :meth:`to_dict`.

        Raises:
            InvalidInputError: not a mapping, missing ``name``/``tcp_mm``, unknown keys, or an
                invalid field.
        """
        if not isinstance(d, Mapping):
            raise InvalidInputError(f"a tool must be an object (dict), got {d!r}.")
        unknown = sorted(set(d) - set(_TOOL_KEYS))
        if unknown:
            raise InvalidInputError(
                f"tool has unknown keys {unknown}; allowed: {list(_TOOL_KEYS)}."
            )
        missing = [k for k in ("name", "tcp_mm") if k not in d]
        if missing:
            raise InvalidInputError(f"tool lacks the keys {missing}.")
        cal = d.get("calibration")
        return cls(
            name=d["name"],
            tcp_mm=d["tcp_mm"],
            abc_deg=d.get("abc_deg", (0.0, 0.0, 0.0)),
            mass_kg=d.get("mass_kg"),
            cog_mm=d.get("cog_mm"),
            load_abc_deg=d.get("load_abc_deg"),
            inertia_kgm2=d.get("inertia_kgm2"),
            notes=d.get("notes", ""),
            calibration=None if cal is None else Calibration.from_dict(cal),
        )
