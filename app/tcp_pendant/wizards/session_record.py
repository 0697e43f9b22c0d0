"""Session record: export a training session as JSON and load it back to replay (grade) it.

A trainer grades from this file: every wizard's recorded flange poses are in it, so loading
rebuilds each wizard and recomputes its result with ``tcpcal``; :func:`replay` checks that the
recomputed result matches the stored one and recomputes the errors against the true tool.

JSON contract (version 1). Lengths: metres in ``*_m`` keys, millimetres in ``*_mm`` keys;
angles in degrees; poses are 4x4 row-major nested lists; times ISO 8601 UTC.

.. code-block:: text

    {
      "format": "tcp-pendant-session",          # constant
      "version": 1,
      "exported_at": "2026-11-22T19:00:00Z",
      "robot": {"name": "kr6",                  # robot key or URDF stem
                "urdf": "/path/kr6.urdf" | null,
                "T_world_base_m": 4x4},
      "mounted_tool": {"key": "pointer", "label": "Pointer",
                       "T_flange_tcp_true_m": 4x4} | null,    # at export time
      "reference_tip_world_m": [x, y, z] | null,
      "touches": [ {"label": str, "T_world_flange_m": 4x4} ],  # the pendant's free touches
      "wizards": [
        {
          "state": {                              # Wizard.to_dict()
            "kind": "xyz4" | "reference" | "three-point" | "abc-world",
            "params": {...},                      # constructor options of that wizard:
                # xyz4: n_points, estimator, assumed_sigma_mm, base_tool (Tool.to_dict or null),
                #       excluded (0-based touch indices)
                # reference: reference_tool (Tool.to_dict), reference_tool_key, new_tool_key,
                #       new_tool_label
                # three-point: tool (Tool.to_dict), variant (1 | 2)
                # abc-world: tool (Tool.to_dict), variant ("6d" | "5d")
            "poses": {"0": {"T_world_flange_m": 4x4, "recorded_at": str}, ...},  # by step
            "step_index": int, "status": "in_progress" | "complete" | "cancelled",
            "resume_status": "in_progress" | "complete", "started_at": str
          },
          "result": {                             # WizardResult.summary(), null if unfinished
            "wizard": str, "method": str, "tcp_mm": [x, y, z], "abc_deg": [a, b, c] | null,
            "per_touch_error_mm": [...], "figures": {name: number}, "warnings": [str],
            "computed_at": str
          } | null,
          "true_tool": {"key": str | null, "T_flange_tcp_true_m": 4x4} | null,
          "truth": TruthComparison.to_dict() | null   # position_error_mm, orientation_error_deg,
                                                      # x_axis_error_deg, inside_ci95, graded,
                                                      # grade, verdict, position_error_vector_mm
        }
      ]
    }
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.wizards.base import Wizard, WizardError, check_pose_m, utc_now_iso
from tcp_pendant.wizards.truth import TruthComparison, compare_with_truth

FORMAT = "tcp-pendant-session"
VERSION = 1
REPLAY_TOLERANCE_MM = 1e-6
REPLAY_TOLERANCE_DEG = 1e-6


class SessionRecordError(WizardError):
    """A session record that cannot be read: not JSON, wrong format or version, bad content."""


@dataclass(frozen=True, eq=False)
class WizardRun:
    """A wizard of the session and, in training mode, the true frame of the tool it calibrates.

    Attributes:
        wizard: the wizard (finished or not).
        true_tool_key: key of the physical tool whose truth applies (the new tool for the
            reference wizard).
        T_flange_tcp_true_m: (4,4) true FLANGE -> TOOL of that tool, metres; None: no truth.
    """

    wizard: Wizard
    true_tool_key: str | None = None
    T_flange_tcp_true_m: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class ReplayCheck:
    """One wizard of a loaded record, recomputed.

    Attributes:
        index: position in ``"wizards"``.
        kind: wizard kind.
        wizard: the rebuilt wizard (recomputed when it was complete).
        matches: recomputed tcp and orientation equal the stored ones within 1e-6 mm / deg
            (True for unfinished wizards, which store no result).
        tcp_diff_mm: ``|tcp_replayed - tcp_stored|`` or None.
        rotation_diff_deg: angle between stored and recomputed orientation, or None.
        truth: errors against the true tool, recomputed (None without truth or result).
        message: plain words.
    """

    index: int
    kind: str
    wizard: Wizard
    matches: bool
    tcp_diff_mm: float | None
    rotation_diff_deg: float | None
    truth: TruthComparison | None
    message: str


def _pose_list(T: Any) -> list[list[float]]:
    return check_pose_m(T).tolist()


def _touch_dict(touch: Any) -> dict[str, Any]:
    if isinstance(touch, Mapping):
        T, label = touch["T_world_flange_m"], touch.get("label", "")
    elif isinstance(touch, tuple):
        T, label = touch
    else:  # tcp_pendant.session.Touch: T_world_flange (metres), label
        T, label = touch.T_world_flange, touch.label
    return {"label": str(label), "T_world_flange_m": _pose_list(T)}


def _run_dict(run: WizardRun | Wizard) -> dict[str, Any]:
    if isinstance(run, Wizard):
        run = WizardRun(run)
    wiz = run.wizard
    res = wiz.finished_result          # a finished wizard closed to resume later keeps its result
    truth = None
    true_tool = None
    if run.T_flange_tcp_true_m is not None:
        true_tool = {"key": run.true_tool_key, "T_flange_tcp_true_m": _pose_list(run.T_flange_tcp_true_m)}
        if res is not None:
            truth = compare_with_truth(res, run.T_flange_tcp_true_m).to_dict()
    return {"state": wiz.to_dict(), "result": None if res is None else res.summary(),
            "true_tool": true_tool, "truth": truth}


def session_to_dict(runs: Sequence[WizardRun | Wizard], *, robot: str, urdf: str | Path | None = None,
                    T_world_base_m: Any = None, mounted_tool: Any = None,
                    reference_tip_world_m: Any = None, touches: Sequence[Any] = ()) -> dict[str, Any]:
    """The session as a JSON-ready dict (see the module docstring for the keys).

    Args:
        runs: wizards of the session (with their true tool in training mode).
        robot: robot name ("kr6", "gp12" or the URDF stem).
        urdf: URDF path, if known.
        T_world_base_m: (4,4) base frame, metres (identity if None).
        mounted_tool: the ``ToolModel`` mounted at export time (key, label, T_flange_tcp_true).
        reference_tip_world_m: reference tip position, metres.
        touches: the pendant's captured touches (``Touch`` objects, ``(T, label)`` tuples or
            dicts with ``T_world_flange_m`` and ``label``).
    """
    tool = None
    if mounted_tool is not None:
        tool = {"key": mounted_tool.key, "label": getattr(mounted_tool, "label", mounted_tool.key),
                "T_flange_tcp_true_m": _pose_list(mounted_tool.T_flange_tcp_true)}
    tip = None
    if reference_tip_world_m is not None:
        tip = [float(v) for v in np.asarray(reference_tip_world_m, dtype=float).reshape(3)]
    return {
        "format": FORMAT, "version": VERSION, "exported_at": utc_now_iso(),
        "robot": {"name": str(robot), "urdf": None if urdf is None else str(urdf),
                  "T_world_base_m": _pose_list(np.eye(4) if T_world_base_m is None else T_world_base_m)},
        "mounted_tool": tool, "reference_tip_world_m": tip,
        "touches": [_touch_dict(t) for t in touches],
        "wizards": [_run_dict(r) for r in runs],
    }


def session_from_controller(controller: Any, runs: Sequence[WizardRun | Wizard], *, robot: str,
                            touches: Sequence[Any] = ()) -> dict[str, Any]:
    """``session_to_dict`` filled from a ``VirtualController`` (base, tool, reference tip, URDF)."""
    kin = getattr(controller, "kinematics", None)
    urdf = getattr(kin, "urdf_path", None)
    return session_to_dict(runs, robot=robot, urdf=urdf, T_world_base_m=controller.T_world_base,
                           mounted_tool=controller.mounted_tool,
                           reference_tip_world_m=controller.reference_tip_world_m, touches=touches)


def dumps(record: Mapping[str, Any]) -> str:
    """The record as JSON text (floats written exactly, so a replay reproduces the numbers)."""
    return json.dumps(record, indent=1, allow_nan=False)


def save_session(path: str | Path, record: Mapping[str, Any]) -> Path:
    """Write the record as JSON to ``path`` and return the path."""
    p = Path(path)
    p.write_text(dumps(record), encoding="utf-8")
    return p


def load_session(source: str | Path | Mapping[str, Any]) -> dict[str, Any]:
    """Read a record (a path, JSON text or an already parsed dict) and check its header.

    Raises:
        SessionRecordError: unreadable file, invalid JSON, wrong ``format`` or ``version``.
    """
    if isinstance(source, Mapping):
        data: Any = dict(source)
    else:
        text = str(source)
        if isinstance(source, Path) or not text.lstrip().startswith("{"):
            try:
                text = Path(source).read_text(encoding="utf-8")
            except OSError as exc:
                raise SessionRecordError(f"Cannot read the session record {source}: {exc}.") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            raise SessionRecordError(f"The session record is not valid JSON ({exc}); "
                                     "export it again from the pendant.") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise SessionRecordError(f"Not a TCP Pendant session record (expected \"format\": \"{FORMAT}\").")
    if data.get("version") != VERSION:
        raise SessionRecordError(f"Session record version {data.get('version')!r} is not supported "
                                 f"(this pendant reads version {VERSION}).")
    if not isinstance(data.get("wizards", []), list):
        raise SessionRecordError("\"wizards\" must be a list.")
    return data


def replay(record: Mapping[str, Any]) -> tuple[ReplayCheck, ...]:
    """Rebuild every wizard of a record, recompute with tcpcal, compare with the stored result.

    Raises:
        SessionRecordError: a wizard entry cannot be rebuilt (the message says which).
    """
    data = load_session(record)
    checks: list[ReplayCheck] = []
    for i, entry in enumerate(data.get("wizards", [])):
        try:
            wiz = Wizard.from_dict(entry["state"])
        except (KeyError, TypeError, ValueError) as exc:
            raise SessionRecordError(f"Wizard {i + 1} of the record cannot be rebuilt: {exc}") from None
        stored = entry.get("result")
        res = wiz.finished_result
        tcp_diff = rot_diff = None
        truth = None
        if stored is None:
            matches = res is None
            message = "unfinished wizard (no result stored)" if matches else \
                "the record stores no result but the wizard is complete"
        elif res is None:
            matches, message = False, "a result is stored but the wizard could not be completed"
        else:
            tcp_diff = float(np.linalg.norm(np.asarray(res.tcp_mm) - np.asarray(stored["tcp_mm"], dtype=float)))
            matches = tcp_diff <= REPLAY_TOLERANCE_MM and res.method == stored.get("method")
            if (stored.get("abc_deg") is None) != (res.abc_deg is None):
                matches = False
            elif res.abc_deg is not None:
                R_stored = Rotation.from_euler("ZYX", stored["abc_deg"], degrees=True)
                R_now = Rotation.from_euler("ZYX", res.abc_deg, degrees=True)
                rot_diff = float(np.degrees((R_stored.inv() * R_now).magnitude()))
                matches = matches and rot_diff <= REPLAY_TOLERANCE_DEG
            message = ("replayed result matches the record" if matches else
                       f"replayed result differs from the record (TCP by {tcp_diff:.3g} mm"
                       + (f", orientation by {rot_diff:.3g} deg" if rot_diff is not None else "") + ")")
            true_tool = entry.get("true_tool")
            if true_tool is not None:
                truth = compare_with_truth(res, true_tool["T_flange_tcp_true_m"])
        checks.append(ReplayCheck(index=i, kind=wiz.kind, wizard=wiz, matches=matches,
                                  tcp_diff_mm=tcp_diff, rotation_diff_deg=rot_diff, truth=truth,
                                  message=message))
    return tuple(checks)
