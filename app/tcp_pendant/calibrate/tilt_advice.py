"""The tilt hint of the wizard dock and the touch scatter its predictions use (no viser).

**Which tilt.** The candidates are the rotation keys A, B, C (each way) of the *active* jog
frame by ``tilts.TILT_DEG``, as the trainee will press them (about the frame's axes through the
TCP): ``R_world_flange' = Exp(s angle a) R_world_flange`` with ``a`` the frame's axis in WORLD.
Only usable ones count (``pendant.tilts``: reachable on the robot model with the tip held, and
not a turn about the tool's own length). Each is scored by tcpcal's predicted TCP error after it
(``candidate_gain``), or, while one more touch cannot give a prediction yet, the least-observed
eigenvalue of the touches' information matrix (``diversity.least_observed``).
When no key of the active frame is usable the other frames are tried, and the hint says how
to switch (the Frame dropdown); in Joint mode it says to set Mode to Cartesian first.

**When.** No hint before the first touch (any orientation will do). Afterwards a tilt is
suggested only while recording here would be clearly worse than after the best tilt: the
orientation is under 0.9 x ``MIN_TILT_DEG`` from a touch, or the best tilt's predicted error is
under 0.8 x the one here (or its least-observed eigenvalue over 1.5 x). Otherwise the hint says
the orientation is good. :class:`TiltAdvisor` also remembers the hint it gave and the flange
orientation then: once the trainee has turned by 0.8 x the tilt since, that same key is not
suggested again (followed, it does not come back unchanged).

**Scatter.** :func:`measured_sigma_mm`: once tcpcal solves the run's touches (XYZ 4-point: four
or more, its minimum), the per-axis scatter of the trainee's own touches, tcpcal's
``noise_sigma = sqrt(sum |e_i|^2 / (3N - 6))`` (methods.md, 4P-3); before that, the scatter of
the trainee's last finished XYZ calibration in this session (its result's ``noise_sigma``); only
without either the wizard's assumed error. :func:`meter_gain` predicts with it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from tcpcal.errors import TcpcalError
from tcpcal.origin import solve_xyz4
from tcpcal.pose_quality import CandidateGain, candidate_gain

from tcp_pendant.calibrate.diversity import MIN_TILT_DEG, least_observed
from tcp_pendant.pendant.jogging import JOG_FRAMES, Jogger, JogMode
from tcp_pendant.pendant.tilts import TILT_DEG, TiltOption, key_label, keyboard_key
from tcp_pendant.translation import ENGLISH, N_, Translator

__all__ = ["MIN_MEASURED_SIGMA_MM", "MeterGain", "TiltAdvice", "TiltAdvisor", "meter_gain", "measured_sigma_mm"]

MIN_MEASURED_SIGMA_MM = 0.02
"""The measured scatter is taken as at least this (mm): three touches that happen to agree
must not promise a perfect result."""


def measured_sigma_mm(wizard: Any) -> float | None:
    """The per-axis scatter of the run's recorded touches (mm), or None: not an XYZ 4-point
    wizard, fewer than four touches, or tcpcal cannot solve them (module docstring)."""
    if getattr(wizard, "kind", "") != "xyz4":
        return None
    poses = wizard.recorded_poses
    rows = [poses[i].T_world_flange_m for i in wizard.solver_touch_steps() if i in poses]
    if len(rows) < 4:
        return None
    R = np.array([T[:3, :3] for T in rows])
    f_mm = np.array([T[:3, 3] for T in rows]) * 1000.0           # metres -> mm for tcpcal
    try:
        sigma = float(solve_xyz4(R, f_mm).noise_sigma)
    except TcpcalError:
        return None
    return max(sigma, MIN_MEASURED_SIGMA_MM) if math.isfinite(sigma) else None


@dataclass(frozen=True)
class MeterGain:
    """The meter's prediction at a candidate orientation.

    Attributes:
        gain: tcpcal's ``candidate_gain`` for ``sigma_mm``.
        sigma_mm: the per-axis touch error it assumes (mm).
        measured: ``sigma_mm`` is the trainee's own scatter (:func:`measured_sigma_mm`), not the
            wizard's assumption.
    """

    gain: CandidateGain
    sigma_mm: float
    measured: bool
    source: str = ""
    """Whose scatter: "your touches" (this run's) or "your last calibration" ("" assumed)."""

    @property
    def basis(self) -> str:
        """"your touches scatter 0.21 mm", "your last calibration scattered 0.21 mm" or
        "assuming 0.5 mm per touch" (English: :meth:`basis_words`)."""
        return self.basis_words()

    def basis_words(self, tr: Translator = ENGLISH) -> str:
        """:attr:`basis` in ``tr``'s language."""
        if not self.measured:
            return tr.gettext("assuming {sigma} mm per touch").format(sigma=f"{self.sigma_mm:g}")
        if self.source == "your touches":
            return tr.gettext("your touches scatter {sigma} mm").format(sigma=f"{self.sigma_mm:.2f}")
        return tr.gettext("your last calibration scattered {sigma} mm").format(sigma=f"{self.sigma_mm:.2f}")


def _last_scatter(earlier: Sequence[Any]) -> float | None:
    """``noise_sigma`` of the latest finished XYZ result among ``earlier`` wizards (mm)."""
    for w in reversed(list(earlier)):
        result = getattr(w, "finished_result", None)
        tcp = getattr(result, "tcp_result", None)
        sigma = getattr(tcp, "noise_sigma", None)
        if sigma is not None and math.isfinite(float(sigma)):
            return max(float(sigma), MIN_MEASURED_SIGMA_MM)
    return None


def meter_gain(wizard: Any, R_world_flange: np.ndarray, earlier: Sequence[Any] = ()) -> MeterGain:
    """``candidate_gain`` of the wizard's other touches and ``R_world_flange`` for the trainee's
    measured scatter (this run's touches, else the last finished calibration among ``earlier``
    wizards of the session), else the wizard's assumed error (as ``wizard.preview``)."""
    sigma, source = measured_sigma_mm(wizard), N_("your touches")
    if sigma is None:
        sigma, source = _last_scatter([w for w in earlier if w is not wizard]), N_("your last calibration")
    measured = sigma is not None
    sigma_mm = float(wizard.assumed_sigma_mm) if sigma is None else sigma
    gain = candidate_gain(wizard.other_rotations(), np.asarray(R_world_flange, dtype=float), sigma=sigma_mm)
    return MeterGain(gain, sigma_mm, measured, source if measured else "")


@dataclass(frozen=True)
class TiltAdvice:
    """The dock's tilt line.

    Attributes:
        option: the tilt suggested (None: none: ``text`` says why).
        switch_to: the jog frame it needs when not the active one ("" when active).
        text: the line (our words and numbers only; markdown bold).
    """

    option: TiltOption | None
    switch_to: str
    text: str


def _score(rots: np.ndarray, R: np.ndarray, sigma_mm: float) -> tuple[float, float]:
    """(predicted TCP error after recording at ``R`` (inf: none yet), least-observed eigenvalue)."""
    after = float(candidate_gain(rots, R, sigma=sigma_mm).predicted_after)
    return after, least_observed(np.concatenate([rots, R[None]]))


def _better(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """``a`` clearly better than ``b`` (module docstring: 0.8 x the error, or 1.5 x the eigenvalue)."""
    if math.isfinite(a[0]):
        return not math.isfinite(b[0]) or a[0] < 0.8 * b[0]
    return not math.isfinite(b[0]) and a[1] > 1.5 * b[1] and a[1] > 1e-6


def _angle_deg(Ra: np.ndarray, Rb: np.ndarray) -> float:
    return float(np.degrees(Rotation.from_matrix(Ra.T @ Rb).magnitude()))


class TiltAdvisor:
    """The tilt hint of one dock (module docstring); remembers the last hint it gave."""

    def __init__(self) -> None:
        self._last: tuple[str, str, int] | None = None      # the hint given, and the orientation
        self._last_R: np.ndarray | None = None              # when it was first given
        self._skip: tuple[str, str, int] | None = None      # a hint followed, and where
        self._skip_R: np.ndarray | None = None

    def advise(self, recorded: np.ndarray, R_world_flange: np.ndarray, jogger: Jogger,
               sigma_mm: float, *, tr: Translator = ENGLISH) -> TiltAdvice | None:
        """The hint for the touches ``recorded`` ((N, 3, 3) ``R_world_flange``) at the flange
        orientation now, in ``tr``'s language; None before the first touch."""
        _ = tr.gettext
        rots = np.asarray(recorded, dtype=float).reshape(-1, 3, 3)
        R_wf = np.asarray(R_world_flange, dtype=float).reshape(3, 3)
        if rots.shape[0] == 0:
            return None
        if self._last is not None and self._last_R is not None and _angle_deg(self._last_R, R_wf) >= 0.8 * TILT_DEG:
            self._skip, self._skip_R, self._last = self._last, R_wf, None      # followed
        skip = (self._skip if self._skip_R is not None and _angle_deg(self._skip_R, R_wf) < 20.0 else None)
        now = _score(rots, R_wf, sigma_mm)
        nearest = min(_angle_deg(R, R_wf) for R in rots)
        good = TiltAdvice(None, "", _("✔ This orientation is a good one for the next touch: bring the "
                                      "tips together and Record."))
        active = jogger.settings.frame
        for frame in (active,) + tuple(f for f in JOG_FRAMES if f != active):
            best = self._best(rots, R_wf, jogger.tilts.options(frame), sigma_mm, skip)
            if best is None:
                continue
            option, score = best
            if nearest >= 0.9 * MIN_TILT_DEG and not _better(score, now):
                return good
            given = (frame, option.reach.key, option.reach.sign)
            if given != self._last:
                self._last, self._last_R = given, R_wf
            return TiltAdvice(option, "" if frame == active else frame,
                              _words(option, score, frame, active, jogger.settings.mode is JogMode.JOINT, tr))
        if nearest >= 0.9 * MIN_TILT_DEG:
            return good
        return TiltAdvice(None, "", _("No 45° tilt is reachable from here with the tip held: press "
                                      "Ready pose and tilt from there."))

    @staticmethod
    def _best(rots: np.ndarray, R_wf: np.ndarray, options: tuple[TiltOption, ...], sigma_mm: float,
              skip: tuple[str, str, int] | None) -> tuple[TiltOption, tuple[float, float]] | None:
        best: tuple[TiltOption, tuple[float, float]] | None = None
        for o in options:
            r = o.reach
            if not o.usable or (r.frame, r.key, r.sign) == skip:
                continue
            R_try = Rotation.from_rotvec(o.axis_world * (r.sign * math.radians(r.angle_deg))).as_matrix() @ R_wf
            score = _score(rots, R_try, sigma_mm)
            if best is None or _better(score, best[1]) or (
                    math.isfinite(score[0]) and math.isfinite(best[1][0]) and score[0] < best[1][0]) or (
                    not math.isfinite(score[0]) and not math.isfinite(best[1][0]) and score[1] > best[1][1]):
                best = (o, score)
        return best


def _words(option: TiltOption, score: tuple[float, float], frame: str, active: str, joint_mode: bool,
           tr: Translator = ENGLISH) -> str:
    """"Tilt next: [set Mode to Cartesian, ][set Jog frame to TOOL, then ]**B −** 45°[ in WORLD]
    (key Shift+5)[ → predicted TCP error **0.80 mm**].", one message per form (word order)."""
    _ = tr.gettext
    r = option.reach
    tilt = dict(tilt=f"**{key_label(r.key, r.sign)}** {r.angle_deg:.0f}°", key=keyboard_key(r.key, r.sign),
                frame=frame)
    if joint_mode and frame != active:
        text = _("Tilt next: set Mode to Cartesian, set Jog frame to {frame}, then {tilt} (key {key})").format(**tilt)
    elif joint_mode:
        text = _("Tilt next: set Mode to Cartesian, then {tilt} (key {key})").format(**tilt)
    elif frame != active:
        text = _("Tilt next: set Jog frame to {frame}, then {tilt} (key {key})").format(**tilt)
    else:
        text = _("Tilt next: {tilt} in {frame} (key {key})").format(**tilt)
    if math.isfinite(score[0]):
        return _("{advice} → predicted TCP error **{error} mm**.").format(advice=text, error=f"{score[0]:.2f}")
    return _("{advice}.").format(advice=text)
