"""Session record: export a training session as JSON and load it back to replay (grade) it.

A trainer grades from this file: every wizard's recorded flange poses are in it, so loading
rebuilds each wizard and recomputes its result with ``tcpcal``; :func:`replay` checks that the
recomputed result matches the stored one and recomputes the errors against the true tool.

JSON contract (version 2; version 1 records are still read: they have no ``honest`` and no
``record_id`` keys). Optional keys added later (``joints_deg``, ``distance_mm``) need no new
version: a record without them reads as before, and an older pendant ignores them.
Lengths: metres in ``*_m`` keys, millimetres in ``*_mm`` keys;
angles in degrees; poses are 4x4 row-major nested lists; times ISO 8601 UTC. The key
``"T_flange_tcp_true_m"`` keeps its version-1 spelling (a contract); in code the same frame is
``T_flange_tool_true_m`` (the hidden true TOOL frame, FLANGE -> TOOL, metres).

.. code-block:: text

    {
      "format": "tcp-pendant-session",          # constant
      "version": 2,
      "honest": false,                          # true: a classroom trainee's record, no truth
      "exported_at": "2026-11-22T19:00:00Z",
      "robot": {"name": "kr6",                  # robot key or URDF stem
                "urdf": "/path/kr6.urdf" | null,
                "T_world_base_m": 4x4},
      "mounted_tool": {"key": "pointer", "label": "Pointer",
                       "T_flange_tcp_true_m": 4x4} | null,    # at export time
      "reference_tip_world_m": [x, y, z] | null,
      "touches": [ {"label": str, "T_world_flange_m": 4x4,   # the pendant's free touches
                    "joints_deg": [j1, ..., jN]} ],          # optional: the joint values
                                                             # when recorded, deg (mm for linear axes)
      "wizards": [
        {
          "state": {                              # Wizard.to_dict()
            "kind": "xyz4" | "reference" | "tcp-zx" | "three-point" | "abc-world" (any registered),
            "params": {...},                      # constructor options of that wizard:
                # xyz4: n_points, estimator, assumed_sigma_mm, base_tool (Tool.to_dict or null),
                #       excluded (0-based touch indices)
                # reference: reference_tool (Tool.to_dict), reference_tool_key, new_tool_key,
                #       new_tool_label
                # three-point: tool (Tool.to_dict), variant (1 | 2)
                # abc-world: tool (Tool.to_dict), variant ("6d" | "5d")
                # tcp-check: tool (Tool.to_dict), slot, angle_deg, check (figures or null)
                # beam: n_orientations (3..5), scan_speed_mm_s, R_flange_tool_base (3x3, the
                #       planning orientation) | null, manual ({title, kind, run_number,
                #       wall_time_s, truth: {position_error_mm, direction_error_deg, grade} |
                #       null}) | null, scan ({events: [{kind: "tip" | "axis",
                #       T_world_flange_m, beam, beam_point_m, beam_dir, on_shaft,
                #       orientation}] (at most 100), duration_s, path_length_m,
                #       skipped: [str] (at most 10)}) | null
                # an honest record sets every "truth" inside params to null
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
                                                  # honest: {"key": str} (no frame), "truth": null
          "record_id": int | null,                # the gradebook's calibration id (classroom)
          "joints_deg": {"0": [j1, ..., jN], ...},  # optional: joint values of the
                                                  # recorded steps (deg; mm linear), by step
          "distance_mm": {"0": 0.42, ...},        # optional: true tool tip to
                                                  # reference tip when each touch step was
                                                  # recorded, mm (>= 0), by step; never in
                                                  # a record exported in an exercise
          "truth": TruthComparison.to_dict() | null   # position_error_mm, orientation_error_deg,
                                                      # x_axis_error_deg, inside_ci95, graded,
                                                      # grade, verdict, position_error_vector_mm
        }
      ]
    }

Loading (a trainer's upload): :func:`parse_session_record` takes the file's **bytes** and parses
them as JSON, nothing else: text is never taken for a path on the server (:func:`read_session_file`
reads a ``pathlib.Path`` for command-line or server-side use; nothing a browser sends reaches it).
Limits, checked before the work they bound, far above a real record (a full lesson of 13
calibrations with up to 20 touches is about 0.09 MB and nests 8 levels):

* size: at most :data:`MAX_RECORD_BYTES` (2 MB), checked on the byte count before decoding;
* nesting: at most :data:`MAX_NESTING_DEPTH` (32) levels of arrays/objects, found by a linear
  scan before ``json.loads`` (so a ``[[[[...`` bomb never reaches the recursive parser);
* counts, after parsing and before any replay: :data:`MAX_WIZARDS` (200) calibrations,
  :data:`MAX_POSES_PER_WIZARD` (100) poses each, :data:`MAX_TOUCHES` (1000) pendant touches.

:func:`load_and_replay` (parse + :func:`replay`) touches no session, so the app runs it off
viser's event loop (``tcp_pendant.views.wizard_menu``).
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.translation import ENGLISH
from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.wizards.base import Wizard, WizardError, check_pose_m, utc_now_iso
from tcp_pendant.wizards.truth import TruthComparison, compare_with_truth

if TYPE_CHECKING:
    import numpy.typing as npt

    from tcp_pendant.controller.controller import VirtualController
    from tcp_pendant.controller.tools import ToolModel

FORMAT = "tcp-pendant-session"
VERSION = 2
READ_VERSIONS = (1, 2)
"""Versions :func:`check_session_record` reads (version 1 has no ``record_id`` and no ``honest``)."""
REPLAY_TOLERANCE_MM = 1e-6
REPLAY_TOLERANCE_DEG = 1e-6

MAX_RECORD_BYTES = 2_000_000
"""Largest record the pendant parses, bytes (a full training session of 13 calibrations with up
to 20 touches exports about 0.09 MB)."""
MAX_NESTING_DEPTH = 32
"""Deepest nesting of JSON arrays/objects (a real record nests 8 levels)."""
MAX_WIZARDS = 200
"""Most calibrations per record (a lesson has a few dozen at most)."""
MAX_POSES_PER_WIZARD = 100
"""Most recorded poses per calibration (the XYZ 4-point wizard takes at most 20)."""
MAX_TOUCHES = 1000
"""Most pendant touches (``"touches"``) per record."""
MAX_JOINTS = 32
"""Most joint values of one touch (``"joints_deg"``)."""


class SessionRecordError(WizardError):
    """A session record that cannot be read: not JSON, wrong format or version, bad content."""


@dataclass(frozen=True, eq=False)
class WizardRun:
    """A wizard of the session and, in training mode, the true frame of the tool it calibrates.

    Attributes:
        wizard: the wizard (finished or not).
        true_tool_key: key of the physical tool whose truth applies (the new tool for the
            reference wizard).
        T_flange_tool_true_m: (4,4) true FLANGE -> TOOL of that tool, metres; None: no truth.
        joints_deg: joint values (deg; mm linear) of the recorded steps, by 0-based step index,
            filled by the app's session as steps are recorded; exported as the
            wizard's ``"joints_deg"`` for the steps still recorded.
        distance_mm: true tool tip to reference tip (mm) when each touch step was recorded, by
            0-based step index, filled by the workflow as steps are recorded;
            exported as the wizard's ``"distance_mm"`` for the steps still recorded.
        distance_hidden: steps recorded while "Hide distance" was on (the result shows their
            distance-at-record next to their error; not exported).
        touch_tools: the physical tool (key) mounted when each step was recorded, by 0-based
            step index (not exported; unknown for poses loaded or restored): a Finish of touches
            made with another tool than their step measures is refused
            (``CalibrationWorkflow.wrong_tool_touch``).
    """

    wizard: Wizard
    true_tool_key: str | None = None
    T_flange_tool_true_m: np.ndarray | None = None
    joints_deg: dict[int, tuple[float, ...]] = field(default_factory=dict)
    distance_mm: dict[int, float] = field(default_factory=dict)
    distance_hidden: set[int] = field(default_factory=set)
    touch_tools: dict[int, str] = field(default_factory=dict)


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


class PendantTouch(Protocol):
    """A touch captured on the pendant (``session.Touch``)."""

    @property
    def T_world_flange(self) -> np.ndarray:
        """(4,4) flange pose in WORLD, metres."""

    @property
    def label(self) -> str: ...

    @property
    def joints_deg(self) -> tuple[float, ...]: ...


TouchLike = PendantTouch | JsonRecord | tuple[np.ndarray, str]
"""A touch as :func:`session_to_dict` takes it: the pendant's, a dict with ``T_world_flange_m``,
``label`` (and ``joints_deg``), or ``(T_world_flange_m, label)``."""


def _pose_list(T: object) -> list[list[float]]:
    return check_pose_m(T).tolist()


def _touch_dict(touch: TouchLike) -> dict[str, object]:
    if isinstance(touch, Mapping):
        T, label = touch["T_world_flange_m"], touch.get("label", "")
    elif isinstance(touch, tuple):
        T, label = touch
    else:  # tcp_pendant.session.Touch: T_world_flange (metres), label, joints_deg
        T, label = touch.T_world_flange, touch.label
    out: dict[str, object] = {"label": str(label), "T_world_flange_m": _pose_list(T)}
    joints = touch.get("joints_deg") if isinstance(touch, Mapping) else getattr(touch, "joints_deg", ())
    if joints:
        out["joints_deg"] = [float(v) for v in joints]
    return out


def _run_dict(run: WizardRun | Wizard, honest: bool = False, record_id: int | None = None,
              with_distances: bool = True) -> dict[str, object]:
    if isinstance(run, Wizard):
        run = WizardRun(run)
    out = _run_entry(run, honest, record_id)
    steps = run.wizard.recorded_poses
    joints = {str(k): [float(v) for v in q] for k, q in sorted(run.joints_deg.items()) if k in steps}
    if joints:                         # optional: the joint values of the recorded steps
        out["joints_deg"] = joints
    distances = {str(k): float(d) for k, d in sorted(run.distance_mm.items()) if k in steps}
    if distances and with_distances:   # optional: distance-at-record of the touch steps
        out["distance_mm"] = distances
    return out


def run_entry(run: WizardRun, *, honest: bool = True, record_id: int | None = None) -> dict[str, object]:
    """One wizard run as a session record's entry (``"state"``, ``"result"``, ``"true_tool"``,
    ``"truth"``, ``"record_id"``, and ``"joints_deg"`` / ``"distance_mm"`` of its recorded
    steps); ``honest``: no truth in it (the classroom keeps the truth apart, in the gradebook).
    The gradebook stores it for each calibration in progress, so a restart gives it back; it
    keeps the distances (the server's copy, never sent to a browser)."""
    return _run_dict(run, honest, record_id)


def step_joints(entry: JsonRecord) -> dict[int, tuple[float, ...]]:
    """A checked record entry's ``"joints_deg"`` by 0-based step index ({} when absent)."""
    raw = entry.get("joints_deg") or {}
    return {int(k): tuple(float(v) for v in q) for k, q in raw.items()}


def step_distances(entry: JsonRecord) -> dict[int, float]:
    """A checked record entry's ``"distance_mm"`` by 0-based step index ({} when absent)."""
    raw = entry.get("distance_mm") or {}
    return {int(k): float(v) for k, v in raw.items()}


def _distance_map(value: object) -> bool:
    """Step index ("0"..) -> finite distance >= 0 mm, at most :data:`MAX_POSES_PER_WIZARD` steps."""
    return isinstance(value, Mapping) and len(value) <= MAX_POSES_PER_WIZARD and all(
        isinstance(k, str) and k.isdigit() and len(k) <= 3
        and isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v >= 0.0
        for k, v in value.items())


def _without_truth(state: dict[str, object]) -> dict[str, object]:
    """A wizard state for an honest record: every ``"truth"`` key inside its params (where a
    wizard keeps figures derived from the hidden truth, e.g. the beam wizard's manual
    comparison) set to null."""
    def strip(value: object, depth: int = 0) -> object:
        if isinstance(value, Mapping) and depth < 8:
            return {k: (None if k == "truth" else strip(v, depth + 1)) for k, v in value.items()}
        return value

    return {**state, "params": strip(state.get("params", {}))}


def _run_entry(run: WizardRun, honest: bool, record_id: int | None) -> dict[str, object]:
    wiz = run.wizard
    res = wiz.result_in(ENGLISH)       # a finished wizard closed to resume later keeps its result; the
                                       # record's words are English whatever the trainee reads
    truth = None
    true_tool = None
    if honest:                         # a trainee's homework: no answer key (graded by the gradebook)
        return {"state": _without_truth(wiz.to_dict()), "result": None if res is None else res.summary(),
                "true_tool": None if run.true_tool_key is None else {"key": run.true_tool_key},
                "truth": None, "record_id": record_id}
    if run.T_flange_tool_true_m is not None:
        true_tool = {"key": run.true_tool_key, "T_flange_tcp_true_m": _pose_list(run.T_flange_tool_true_m)}
        if res is not None:
            truth = compare_with_truth(res, run.T_flange_tool_true_m).to_dict()
    return {"state": wiz.to_dict(), "result": None if res is None else res.summary(),
            "true_tool": true_tool, "truth": truth, "record_id": record_id}


def session_to_dict(runs: Sequence[WizardRun | Wizard], *, robot: str, urdf: str | Path | None = None,
                    T_world_base_m: npt.ArrayLike | None = None, mounted_tool: ToolModel | None = None,
                    reference_tip_world_m: npt.ArrayLike | None = None, touches: Sequence[TouchLike] = (),
                    honest: bool = False,
                    record_ids: Mapping[int, int] | None = None, with_distances: bool = True) -> dict[str, object]:
    """The session as a JSON-ready dict (see the module docstring for the keys).

    Args:
        runs: wizards of the session (with their true tool in training mode).
        robot: robot name ("kr6", "gp12" or the URDF stem).
        urdf: URDF path, if known.
        T_world_base_m: (4,4) base frame, metres (identity if None).
        mounted_tool: the ``ToolModel`` mounted at export time (key, label, T_flange_tool_true).
        reference_tip_world_m: reference tip position, metres.
        touches: the pendant's captured touches (``Touch`` objects, ``(T, label)`` tuples or
            dicts with ``T_world_flange_m`` and ``label``).
        honest: a trainee's record in a class: no true TOOL frame anywhere, no
            errors against it, no server path (``robot.urdf`` null); the trainer grades it
            against the gradebook by each wizard's ``record_id``.
        record_ids: run index -> gradebook calibration id (``record_id`` of each wizard).
        with_distances: each wizard's ``"distance_mm"`` (the true tip-to-reference distance of
            every touch) is written. False in an exercise: with the touches' flange poses and
            the reference tip, the distances d_i give the true TCP t by trilateration,
            ``|R_i t + p_i - r| = d_i`` (four touches in general position suffice), without a
            single real touch.
    """
    ids = {} if record_ids is None else dict(record_ids)
    tool = None
    if mounted_tool is not None:
        tool = {"key": mounted_tool.key, "label": getattr(mounted_tool, "label", mounted_tool.key)}
        if not honest:
            tool["T_flange_tcp_true_m"] = _pose_list(mounted_tool.T_flange_tool_true)
    tip = None
    if reference_tip_world_m is not None:
        tip = [float(v) for v in np.asarray(reference_tip_world_m, dtype=float).reshape(3)]
    return {
        "format": FORMAT, "version": VERSION, "exported_at": utc_now_iso(),
        "honest": bool(honest),
        "robot": {"name": str(robot), "urdf": None if urdf is None or honest else str(urdf),
                  "T_world_base_m": _pose_list(np.eye(4) if T_world_base_m is None else T_world_base_m)},
        "mounted_tool": tool, "reference_tip_world_m": tip,
        "touches": [_touch_dict(t) for t in touches],
        "wizards": [_run_dict(r, honest, ids.get(i), with_distances) for i, r in enumerate(runs)],
    }


def session_from_controller(controller: VirtualController, runs: Sequence[WizardRun | Wizard], *, robot: str,
                            touches: Sequence[TouchLike] = (), honest: bool = False,
                            record_ids: Mapping[int, int] | None = None,
                            with_distances: bool = True) -> dict[str, object]:
    """``session_to_dict`` filled from a ``VirtualController`` (base, tool, reference tip, URDF;
    ``honest``, ``record_ids`` and ``with_distances`` as there)."""
    kin = getattr(controller, "kinematics", None)
    urdf = getattr(kin, "urdf_path", None)
    return session_to_dict(runs, robot=robot, urdf=urdf, T_world_base_m=controller.T_world_base,
                           mounted_tool=controller.mounted_tool,
                           reference_tip_world_m=controller.reference_tip_world_m, touches=touches,
                           honest=honest, record_ids=record_ids, with_distances=with_distances)


def dumps(record: JsonRecord) -> str:
    """The record as JSON text (floats written exactly, so a replay reproduces the numbers)."""
    return json.dumps(record, indent=1, allow_nan=False)


def save_session(path: str | Path, record: JsonRecord) -> Path:
    """Write the record as JSON to ``path`` and return the path."""
    p = Path(path)
    p.write_text(dumps(record), encoding="utf-8")
    return p


def _limit_error(what: str, found: str, limit: str) -> SessionRecordError:
    return SessionRecordError(
        f"The session record {what} {found}; the pendant loads records with at most {limit} "
        "(a full training session is far below that). Load a record exported by the pendant, "
        "or split the session into several records.")


def check_record_size(n_bytes: int) -> None:
    """Refuse a record of ``n_bytes`` bytes above :data:`MAX_RECORD_BYTES` (before any parsing).

    Raises:
        SessionRecordError: too large (the message names the limit).
    """
    if n_bytes > MAX_RECORD_BYTES:
        raise _limit_error("is", f"{n_bytes:,} bytes ({n_bytes / 1e6:.1f} MB)",
                           f"{MAX_RECORD_BYTES:,} bytes ({MAX_RECORD_BYTES / 1e6:g} MB)")


# A string literal, or an unterminated one running to the end: every '"' starts a match, so the
# scan never restarts inside a string (linear time, also for a run of escaped quotes).
_JSON_STRING = re.compile(rb'"[^"\\]*(?:\\.[^"\\]*)*(?:"|\\?\Z)', re.DOTALL)


def json_nesting_depth(data: bytes) -> int:
    """Deepest nesting of JSON arrays and objects in ``data`` (UTF-8 JSON text), without parsing
    it: string literals are cut out, then the brackets are counted (linear time, no recursion).

    Brackets are ASCII, and no byte of a multi-byte UTF-8 character is ASCII, so the count holds
    for any UTF-8 text; for text that is not JSON the number is only an upper-bound guess.
    """
    skeleton = np.frombuffer(_JSON_STRING.sub(b"", bytes(data)), dtype=np.uint8)
    if skeleton.size == 0:
        return 0
    step = np.isin(skeleton, (ord("["), ord("{"))).astype(np.int32) - \
        np.isin(skeleton, (ord("]"), ord("}"))).astype(np.int32)
    return int(max(0, np.cumsum(step).max()))


def _joint_list(value: object) -> bool:
    """A list of at most :data:`MAX_JOINTS` finite numbers (a touch's joint values)."""
    return isinstance(value, list) and len(value) <= MAX_JOINTS and all(
        isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)


def check_session_record(data: object) -> JsonRecord:
    """Check a parsed record: header (``format``, ``version``), the types of ``wizards`` and
    ``touches`` and the count limits (:data:`MAX_WIZARDS`, :data:`MAX_POSES_PER_WIZARD`,
    :data:`MAX_TOUCHES`), which bound the cost of :func:`replay`. Returns a shallow copy.

    Raises:
        SessionRecordError: wrong format or version, bad structure, a limit exceeded.
    """
    if not isinstance(data, Mapping) or data.get("format") != FORMAT:
        raise SessionRecordError(f"Not a TCP Pendant session record (expected \"format\": \"{FORMAT}\").")
    data = dict(data)
    version = data.get("version")
    if isinstance(version, bool) or version not in READ_VERSIONS:
        raise SessionRecordError(f"Session record version {version!r} is not supported "
                                 f"(this pendant reads versions {', '.join(map(str, READ_VERSIONS))}).")
    wizards = data.get("wizards", [])
    if not isinstance(wizards, list):
        raise SessionRecordError("\"wizards\" must be a list.")
    if len(wizards) > MAX_WIZARDS:
        raise _limit_error("holds", f"{len(wizards)} calibrations", f"{MAX_WIZARDS} calibrations")
    touches = data.get("touches", [])
    if not isinstance(touches, list):
        raise SessionRecordError("\"touches\" must be a list.")
    if len(touches) > MAX_TOUCHES:
        raise _limit_error("holds", f"{len(touches)} pendant touches", f"{MAX_TOUCHES} pendant touches")
    for i, touch in enumerate(touches):          # "joints_deg" is optional (older records lack it)
        joints = touch.get("joints_deg") if isinstance(touch, Mapping) else None
        if joints is not None and not _joint_list(joints):
            raise SessionRecordError(f"Touch {i + 1} of the record: \"joints_deg\" must be a list of at most "
                                     f"{MAX_JOINTS} finite numbers (degrees), got {joints!r:.60}.")
    for i, entry in enumerate(wizards):
        state = entry.get("state") if isinstance(entry, Mapping) else None
        rid = entry.get("record_id") if isinstance(entry, Mapping) else None
        if rid is not None and (isinstance(rid, bool) or not isinstance(rid, int) or rid < 1):
            raise SessionRecordError(f"Wizard {i + 1} of the record: \"record_id\" must be a whole "
                                     f"number >= 1 or null, got {rid!r:.40}.")
        if not isinstance(state, Mapping):
            raise SessionRecordError(f"Wizard {i + 1} of the record has no \"state\" object.")
        poses = state.get("poses", {})
        if not isinstance(poses, Mapping):
            raise SessionRecordError(f"Wizard {i + 1} of the record: \"poses\" must be an object.")
        if len(poses) > MAX_POSES_PER_WIZARD:
            raise _limit_error(f"has, in wizard {i + 1},", f"{len(poses)} touches",
                               f"{MAX_POSES_PER_WIZARD} touches per calibration")
        joints = entry.get("joints_deg")
        if joints is not None and not (isinstance(joints, Mapping) and len(joints) <= MAX_POSES_PER_WIZARD
                                       and all(_joint_list(v) for v in joints.values())):
            raise SessionRecordError(f"Wizard {i + 1} of the record: \"joints_deg\" must map steps to lists of "
                                     f"at most {MAX_JOINTS} finite numbers (degrees).")
        distances = entry.get("distance_mm")     # optional
        if distances is not None and not _distance_map(distances):
            raise SessionRecordError(f"Wizard {i + 1} of the record: \"distance_mm\" must map step numbers "
                                     f"(\"0\", \"1\", ...) to distances in mm (finite, 0 or more), "
                                     f"got {distances!r:.60}.")
        true_tool = entry.get("true_tool")
        if true_tool is not None:
            try:
                if not isinstance(true_tool, Mapping) or not isinstance(true_tool.get("key"), (str, type(None))):
                    raise WizardError("it must be {\"key\": text or null, \"T_flange_tool_true_m\": 4x4}")
                if version == 1 or "T_flange_tcp_true_m" in true_tool:   # version 2: honest records have none
                    check_pose_m(true_tool.get("T_flange_tcp_true_m"), what="true TOOL frame")
            except (WizardError, TypeError, ValueError) as exc:
                raise SessionRecordError(f"Wizard {i + 1} of the record: bad \"true_tool\" ({exc}).") from None
    return data


def parse_session_record(data: bytes) -> JsonRecord:
    """Parse an uploaded (or read) record: bytes of UTF-8 JSON, nothing else (never a path).

    The limits are checked before the work they bound: the size on ``len(data)`` before
    decoding, the nesting depth by :func:`json_nesting_depth` before ``json.loads``, the counts
    (:func:`check_session_record`) after parsing and before any replay.

    Args:
        data: the file's bytes (``bytes``, ``bytearray`` or ``memoryview``).

    Raises:
        SessionRecordError: too large, too deep, not UTF-8, not JSON, not a session record,
            too many wizards or touches. The message says what is wrong and what to do.
        TypeError: ``data`` is not bytes (a ``str`` is refused: it could be taken for a path).
    """
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise TypeError(f"parse_session_record takes the record's bytes, not {type(data).__name__}.")
    data = bytes(data)
    check_record_size(len(data))
    depth = json_nesting_depth(data)
    if depth > MAX_NESTING_DEPTH:
        raise _limit_error("nests", f"{depth} levels deep", f"{MAX_NESTING_DEPTH} levels of nesting")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise SessionRecordError("The session record is not a text (JSON) file; "
                                 "export it again from the pendant.") from None
    try:
        parsed = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        raise SessionRecordError(f"The session record is not valid JSON ({exc}); "
                                 "export it again from the pendant.") from None
    return check_session_record(parsed)


def read_session_file(path: Path) -> JsonRecord:
    """Read a record from the server's disk (command line and server-side use only: nothing a
    browser sends reaches this). Only regular files are read (a FIFO or device is refused
    without blocking), at most :data:`MAX_RECORD_BYTES` + 1 bytes, then
    :func:`parse_session_record`.

    Args:
        path: a ``pathlib.Path`` (a ``str`` is refused, so text is never taken for a path).

    Raises:
        SessionRecordError: unreadable, not a regular file, or a bad record.
        TypeError: ``path`` is not a ``Path``.
    """
    if not isinstance(path, Path):
        raise TypeError(f"read_session_file takes a pathlib.Path, not {type(path).__name__}.")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise SessionRecordError(f"Cannot read the session record {path}: {exc.strerror or exc}.") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise SessionRecordError(f"Cannot read the session record {path}: not a regular file.")
        with os.fdopen(fd, "rb", closefd=False) as f:
            data = f.read(MAX_RECORD_BYTES + 1)
    except OSError as exc:
        raise SessionRecordError(f"Cannot read the session record {path}: {exc.strerror or exc}.") from None
    finally:
        os.close(fd)
    return parse_session_record(data)


@dataclass(frozen=True, eq=False)
class LoadedRecord:
    """A parsed, checked and replayed record, ready to be added to a session.

    Attributes:
        record: the record (checked by :func:`check_session_record`).
        checks: one :class:`ReplayCheck` per wizard, in order.
    """

    record: JsonRecord
    checks: tuple[ReplayCheck, ...]


def load_and_replay(source: bytes | str | JsonRecord) -> LoadedRecord:
    """Parse (bytes, or ``str`` as JSON text: never a path) or check (a dict) a record, then
    :func:`replay` it. Pure: touches no session, so it can run in a worker thread.

    Raises:
        SessionRecordError: see :func:`parse_session_record` and :func:`replay`.
        TypeError: another type (a ``Path``: use :func:`read_session_file`).
    """
    if isinstance(source, str):
        source = source.encode("utf-8")
    if isinstance(source, (bytes, bytearray, memoryview)):
        data = parse_session_record(source)
    elif isinstance(source, Mapping):
        data = check_session_record(source)
    else:
        raise TypeError(f"A session record is bytes, JSON text or a dict, not {type(source).__name__} "
                        "(read a file with read_session_file).")
    return LoadedRecord(data, replay(data))


def replay(record: JsonRecord) -> tuple[ReplayCheck, ...]:
    """Rebuild every wizard of a record, recompute with tcpcal, compare with the stored result.

    Raises:
        SessionRecordError: a wizard entry cannot be rebuilt (the message says which).
    """
    data = check_session_record(record)
    checks: list[ReplayCheck] = []
    for i, entry in enumerate(data.get("wizards", [])):
        try:
            wiz = Wizard.from_dict(entry["state"])
        except (AttributeError, KeyError, TypeError, ValueError) as exc:
            raise SessionRecordError(f"Wizard {i + 1} of the record cannot be rebuilt: {exc}") from None
        try:
            checks.append(_check_entry(i, entry, wiz))
        except (AttributeError, KeyError, TypeError, ValueError, IndexError) as exc:
            raise SessionRecordError(f"Wizard {i + 1} of the record: its stored result cannot be "
                                     f"compared ({type(exc).__name__}: {exc}).") from None
    return tuple(checks)


def _check_entry(i: int, entry: JsonRecord, wiz: Wizard) -> ReplayCheck:
    """Compare one rebuilt wizard with its stored result and truth (see :func:`replay`)."""
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
        if true_tool is not None and true_tool.get("T_flange_tcp_true_m") is not None:
            truth = compare_with_truth(res, true_tool["T_flange_tcp_true_m"])
    return ReplayCheck(index=i, kind=wiz.kind, wizard=wiz, matches=matches,
                       tcp_diff_mm=tcp_diff, rotation_diff_deg=rot_diff, truth=truth,
                       message=message)
