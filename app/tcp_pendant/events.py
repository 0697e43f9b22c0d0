"""What happened in a pendant session: the typed events its change signal carries (no viser).

A command of the session (``tcp_pendant.session.Session``) ends in one ``SessionChange``; the
flags there say what to re-render, and ``SessionChange.events`` says what happened, with the
facts taken at the moment it happened (the flange pose, joints and distance of a touch are
those at Record, not at the signal). The calibration workflow (``calibrate.workflow``) makes
the run and touch events where they happen; the session adds the crash. The classroom recorder
maps them one to one onto the gradebook, in the order they happened.

Units: metres for poses, degrees for joints (mm for a prismatic joint), mm for distances.
Run indices are 0-based positions in ``CalibrationWorkflow.runs`` (a list that only grows).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "Crash",
    "RunCancelled",
    "RunFinished",
    "RunResumed",
    "RunStarted",
    "SessionEvent",
    "ToolSaved",
    "TouchRecorded",
]


def _frozen(array: np.ndarray | None) -> np.ndarray | None:
    if array is None:
        return None
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class RunStarted:
    """A wizard run was opened in this session (not one loaded from a record file).

    Attributes:
        run_index: its index in the workflow's runs.
        kind: the wizard kind (``Wizard.kind``), title: its label.
        tool_key: the physical tool whose truth grades it (None: none).
        T_flange_tool_true_m: that tool's hidden true TOOL frame, (4,4) m, or None.
    """

    run_index: int
    kind: str
    title: str
    tool_key: str | None
    T_flange_tool_true_m: np.ndarray | None

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_flange_tool_true_m", _frozen(self.T_flange_tool_true_m))


@dataclass(frozen=True, eq=False)
class TouchRecorded:
    """A pose was recorded at a wizard step (by Record, by Auto-touch, or taken over from the
    Jog tab's free touches when a 4-point starts from them).

    Attributes:
        run_index, step: where (0-based step).
        T_world_flange_m: the recorded flange pose in WORLD, (4,4) m.
        joints_deg: joint values when recorded (deg; mm for a prismatic joint); () unknown.
        distance_mm: true tool tip to reference tip when recorded (nan: unknown).
        auto: recorded by Auto-touch (the controller), not by hand.
        overwrite: the step had a pose before, which this one replaces.
    """

    run_index: int
    step: int
    T_world_flange_m: np.ndarray
    joints_deg: tuple[float, ...]
    distance_mm: float
    auto: bool
    overwrite: bool

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_world_flange_m", _frozen(self.T_world_flange_m))
        object.__setattr__(self, "joints_deg", tuple(float(v) for v in self.joints_deg))


@dataclass(frozen=True, eq=False)
class RunFinished:
    """A run computed its result (again, after Back: the newer result replaces the older).

    Attributes:
        run_index: which run; result: its ``WizardResult``.
        T_flange_tool_true_m: the true TOOL frame it is graded against now, (4,4) m (a step's
            tool change may have mounted another tool since the start), or None.
    """

    run_index: int
    result: object
    T_flange_tool_true_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "T_flange_tool_true_m", _frozen(self.T_flange_tool_true_m))


@dataclass(frozen=True)
class RunCancelled:
    """A run was left (Cancel or Close, or another run was started).

    Attributes:
        run_index: which run.
        finished: it had a result when left (a finished run stays finished).
    """

    run_index: int
    finished: bool


@dataclass(frozen=True)
class RunResumed:
    """A cancelled run was put back on show."""

    run_index: int


@dataclass(frozen=True)
class Crash:
    """The tool went into the reference tip (the touch geometry turned ``crashed``).

    Attributes:
        penetration_mm: how deep, mm (nan: unknown).
        run_index: the run open then (None: none open).
    """

    penetration_mm: float
    run_index: int | None


@dataclass(frozen=True)
class ToolSaved:
    """A calibration result was saved to the tool library.

    Attributes:
        run_index: the run saved from; slot: the library slot; name: the tool's name.
    """

    run_index: int | None
    slot: int
    name: str


SessionEvent = RunStarted | TouchRecorded | RunFinished | RunCancelled | RunResumed | Crash | ToolSaved
"""Every event a ``SessionChange`` may carry."""
