"""What a pendant session remembers of the touches it recorded, beside the wizards (no viser).

A :class:`TouchMemory` belongs to one ``CalibrationWorkflow``. It keeps the joints (radians)
where each pose still held by a run was recorded (a TCP check's spin starts there), which steps
of each run Auto-touch recorded (the beam wizard's lesson counts them), and the direction of
each run's last Auto-touch (the next one comes from another).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from tcp_pendant.wizards.base import RecordedPose
from tcp_pendant.wizards.session_record import WizardRun

__all__ = ["TouchMemory"]


class TouchMemory:
    """Joints at record, Auto-touch's steps and directions of one session (module docstring)."""

    def __init__(self) -> None:
        self._record_q: dict[int, tuple[RecordedPose, np.ndarray]] = {}   # id(pose) -> (pose, joints rad)
        self._auto_steps: dict[int, set[int]] = {}     # run -> steps whose pose Auto-touch recorded
        self._directions: dict[int, tuple[float, float, float]] = {}   # run -> last auto-touch direction

    def recorded(self, run_index: int, step: int, pose: RecordedPose, q_rad: np.ndarray, *, auto: bool,
                 runs: Iterable[WizardRun]) -> None:
        """``pose`` was just recorded at ``step`` of run ``run_index`` with the robot at
        ``q_rad`` (by Auto-touch: ``auto``); the poses no run of ``runs`` holds any more are
        forgotten (a step recorded again, a run's touches dropped), so a session that records
        for hours keeps only what its runs hold."""
        auto_steps = self._auto_steps.setdefault(run_index, set())
        if auto:
            auto_steps.add(step)
        else:
            auto_steps.discard(step)
        self._record_q[id(pose)] = (pose, q_rad.copy())
        held = {id(p) for r in runs for p in r.wizard.recorded_poses.values()}
        for key in [k for k in self._record_q if k not in held]:
            del self._record_q[key]

    def joints_at_record(self, pose: RecordedPose) -> np.ndarray | None:
        """The joints (rad) where ``pose`` was recorded in this session (None: not known, e.g.
        a pose loaded from a record)."""
        known = self._record_q.get(id(pose))
        return None if known is None or known[0] is not pose else known[1].copy()

    def auto_touches(self, run_index: int, steps: Iterable[int]) -> int:
        """How many of ``steps`` of run ``run_index`` Auto-touch recorded."""
        return len(self._auto_steps.get(run_index, set()) & set(steps))

    def direction(self, run_index: int | None) -> tuple[float, float, float] | None:
        """The direction (tilt, azimuth, spin; degrees) of run ``run_index``'s last Auto-touch."""
        return None if run_index is None else self._directions.get(run_index)

    def note_direction(self, run_index: int, direction_deg: tuple[float, float, float]) -> None:
        """Run ``run_index``'s last Auto-touch came from ``direction_deg``."""
        self._directions[run_index] = direction_deg
