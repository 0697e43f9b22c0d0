"""A wizard's touches as the POSES.csv that ``tcpcal solve`` reads ("Export touches (CSV)"), so
that a student can solve them again with the command line (docs/cli.md "POSES.csv").

Columns: ``name`` (the step: ``P1``, ``P2``, ...; the tcp-zx wizard's ``Z1``, ``X1``), the
flange pose in WORLD (``x, y, z`` mm; KUKA ``a, b, c`` degrees, ``R = Rz(A) Ry(B) Rx(C)``,
methods.md section 6), ``role`` (tcp-zx only: ``touch``, ``z``, ``x``) and the joint values
``j1..jN`` (degrees; mm for a linear axis) when every row has them. Numbers are written in full
(``repr``), so the solve reproduces the wizard's poses exactly. The first line is a comment
(the reader skips ``#`` lines) with the command that solves the file, its options filled in
from what the trainee gave the wizard (the calibrated tool's data from the library, the
variant).

Only what the trainee measured: the flange poses and joints of the recorded steps. Never the
true TCP, the true distance of a touch or the swapped tool, so the file gives no answer in an
exercise. The rows are the solver's rows in its order (``Wizard.solver_touch_steps`` for a
4-point, every step of the others), all touches included: a result computed with outliers
dropped or another estimator is the solve's with ``without_outliers`` or ``--method``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcp_pendant.translation import ENGLISH, Translator
from tcp_pendant.wizards import Wizard

__all__ = ["EXPORTABLE", "TOUCHES_CSV_FILENAME", "touches_csv_filename", "wizard_touches_csv"]

EXPORTABLE = ("xyz4", "reference", "three-point", "abc-world", "tcp-zx")
"""The wizard kinds whose touches ``tcpcal solve`` reads (the command is the kind)."""
TOUCHES_CSV_FILENAME = "{kind}-touches.csv"
"""The download's file name (``kind``: the wizard's kind)."""


def touches_csv_filename(wizard: Wizard) -> str:
    """The download's name: ``xyz4-touches.csv`` and so on."""
    return TOUCHES_CSV_FILENAME.format(kind=wizard.kind)


def _mm3(values: Any) -> str:
    return ",".join(f"{float(v):.6f}".rstrip("0").rstrip(".") for v in values)


def _command(wizard: Any) -> str:
    """The ``tcpcal solve`` line that solves the file (options from the wizard's own inputs)."""
    kind = wizard.kind
    file = touches_csv_filename(wizard)
    if kind == "reference":
        return f"tcpcal solve reference {file} --known-tcp {_mm3(wizard.reference_tool.tcp_mm)}"
    if kind == "three-point":
        return f"tcpcal solve three-point {file} --tcp {_mm3(wizard.tool.tcp_mm)} --variant {wizard.variant}"
    if kind == "abc-world":
        current = f" --current-abc {_mm3(wizard.tool.abc_deg)}" if wizard.variant == "5d" else ""
        return f"tcpcal solve abc-world {file} --variant {wizard.variant}{current}"
    return f"tcpcal solve {kind} {file}"


def _rows(wizard: Wizard) -> list[int]:
    poses = wizard.recorded_poses
    if wizard.kind == "xyz4":
        return [i for i in wizard.solver_touch_steps() if i in poses]
    return sorted(poses)


def wizard_touches_csv(wizard: Wizard, joints_deg: Mapping[int, Sequence[float]] | None = None, *,
                       tr: Translator = ENGLISH) -> str:
    """The recorded steps of ``wizard`` as POSES.csv text (module docstring; the same in every
    language); ``joints_deg``: the joint values by 0-based step (the workflow's
    ``WizardRun.joints_deg``).

    Raises:
        ValueError: a wizard ``tcpcal solve`` has no command for, or no step recorded yet (in
            ``tr``'s language).
    """
    if wizard.kind not in EXPORTABLE:
        raise ValueError(tr.gettext("The {method} has no touches tcpcal solve reads; export the session record "
                                    "instead.").format(method=tr.gettext(wizard.title)))
    steps = _rows(wizard)
    if not steps:
        raise ValueError(tr.gettext("No step recorded yet: record the wizard's steps first, then export them."))
    joints = {i: tuple(float(v) for v in (joints_deg or {}).get(i, ())) for i in steps}
    n = {len(j) for j in joints.values()}
    n_joints = n.pop() if len(n) == 1 else 0
    with_role = wizard.kind == "tcp-zx"
    header = ["name", "x", "y", "z", "a", "b", "c", *(["role"] if with_role else []),
              *(f"j{k + 1}" for k in range(n_joints))]
    lines = [f"# {_command(wizard)}", ",".join(header)]
    counts: dict[str, int] = {}
    for i in steps:
        T = np.asarray(wizard.recorded_poses[i].T_world_flange_m, dtype=float)
        abc = Rotation.from_matrix(T[:3, :3]).as_euler("ZYX", degrees=True)
        role = wizard.steps[i].role if with_role else "touch"
        counts[role] = counts.get(role, 0) + 1
        name = f"{'P' if role == 'touch' else role[:1].upper()}{counts[role]}" if with_role else f"P{i + 1}"
        cells = [name, *(repr(float(v)) for v in (*(T[:3, 3] * 1000.0), *abc))]
        if with_role:
            cells.append(role)
        cells += [repr(v) for v in joints[i][:n_joints]]
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"
