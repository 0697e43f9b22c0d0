"""Common machinery of the calibration wizards: steps, navigation, recording, results.

A wizard is a state machine that knows nothing of viser. It is fed flange poses
``T_world_flange_m`` (4x4, **metres**, as the virtual controller gives them), converts them to
**millimetres** for ``tcpcal`` (which is unit-agnostic: its results then come out in mm), and
calls ``tcpcal`` for every bit of calibration math. Views render it; the app acts on it.

Life cycle (``status``)::

    "in_progress" --next() on the last step--> "complete" --back()/add_point()--> "in_progress"
          |  ^                                     |
   cancel()  resume()                           cancel()
          v  |                                     v
        "cancelled"  (nothing recorded is lost; resume() returns to where the user was)

Navigation: ``record()`` stores the pose of the current step (re-recording overwrites it) and
does not move; ``next()`` moves on once the current step is recorded, and on the last step
computes the result (``tcpcal`` errors become :class:`CalibrationFailedError`, the wizard stays
where it was so the user can re-record); ``back()`` moves back without deleting anything.
"""

from __future__ import annotations

import abc
import dataclasses
import datetime as _dt
import math
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import ClassVar, Literal, Protocol

import numpy as np
import numpy.typing as npt

from tcpcal.errors import TcpcalError
from tcpcal.origin import TcpResult
from tcpcal.orientation import OrientationResult
from tcpcal.pose_quality import CandidateGain
from tcpcal.tool import Calibration, Tool

from tcp_pendant.controller.tools import shown_tool_label
from tcp_pendant.json_shapes import JsonRecord
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcp_pendant.wizards.describe import (
    AutoRole,
    OptionError,
    StartContext,
    StepRole,
    WizardOption,
    WizardStart,
)

M_TO_MM = 1000.0
"""Metres (controller) to millimetres (tcpcal input and every ``*_mm`` figure)."""

Status = Literal["in_progress", "complete", "cancelled"]


class WizardError(ValueError):
    """Base of every error a wizard raises: wrong state, bad input. The message says what to do."""


class InvalidPoseError(WizardError):
    """A pose handed to ``record`` or ``preview`` is not a finite rigid 4x4 transform."""


class WizardStateError(WizardError):
    """The action is not possible in the wizard's current state (e.g. Next before Record)."""


class CalibrationFailedError(WizardError):
    """``tcpcal`` could not compute a result from the recorded poses (message from tcpcal)."""

    def __init__(self, message: str, cause: TcpcalError | None = None) -> None:
        super().__init__(message)
        self.cause = cause


def utc_now_iso() -> str:
    """Current time, ISO 8601 UTC with seconds (``2026-11-22T18:55:17Z``)."""
    return _dt.datetime.now(_dt.timezone.utc).replace(microsecond=0).isoformat().replace("+00:00", "Z")


def finite_number(value: object, what: str, *, low: float | None = None, high: float | None = None) -> float:
    """A number from untrusted input (a session record's stored figures, a start option), checked.

    Args:
        value: what was given.
        what: its name in the message ("TCP check's angle": "The TCP check's angle must ...").
        low: inclusive lower bound (None: none).
        high: inclusive upper bound (None: none).

    Raises:
        WizardError: a bool, not a number, not finite, or out of the bounds (naming ``what``).
    """
    if isinstance(value, bool):
        raise WizardError(f"The {what} must be a number, got {value!r:.40}.")
    try:
        x = float(value)  # type: ignore[arg-type]  # any value: what float() refuses is refused
    except (TypeError, ValueError):
        raise WizardError(f"The {what} must be a number, got {value!r:.40}.") from None
    if low is None and high is None:
        if not math.isfinite(x):
            raise WizardError(f"The {what} must be finite, got {value!r:.40}.")
    elif not math.isfinite(x) or (low is not None and x < low) or (high is not None and x > high):
        raise WizardError(f"The {what} must be a finite number in "
                          f"{'-inf' if low is None else f'{low:g}'}..{'inf' if high is None else f'{high:g}'}"
                          f", got {value!r:.40}.")
    return x


def check_pose_m(T_world_flange_m: object, *, what: str = "flange pose") -> np.ndarray:
    """Validate a rigid transform in metres and return it as a float (4,4) copy.

    Raises:
        InvalidPoseError: wrong shape, NaN/inf, bottom row not (0,0,0,1), or a rotation block
            that is not orthonormal with determinant +1 within 1e-6.
    """
    try:
        T = np.array(T_world_flange_m, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InvalidPoseError(f"The {what} is not a 4x4 numeric matrix: {exc}.") from None
    if T.shape != (4, 4):
        raise InvalidPoseError(f"The {what} must be a 4x4 matrix, got shape {T.shape}.")
    if not np.all(np.isfinite(T)):
        raise InvalidPoseError(f"The {what} contains NaN or infinity; read the pose again.")
    if not np.allclose(T[3], [0.0, 0.0, 0.0, 1.0], atol=1e-9):
        raise InvalidPoseError(f"The {what} has bottom row {T[3].tolist()}, expected [0, 0, 0, 1].")
    R = T[:3, :3]
    if not np.allclose(R.T @ R, np.eye(3), atol=1e-6) or np.linalg.det(R) < 0.0:
        raise InvalidPoseError(
            f"The rotation of the {what} is not a proper orthonormal matrix within 1e-6."
        )
    return T


def rotation_and_position_mm(T_world_flange_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split a flange pose in metres into ``R_world_flange`` (3,3) and ``p_world_flange`` in mm."""
    return T_world_flange_m[:3, :3].copy(), T_world_flange_m[:3, 3] * M_TO_MM


class MeterWizard(Protocol):
    """A wizard that declares ``diversity_meter`` (XYZ 4-point, TCP & Z, X), as the meter reads it."""

    assumed_sigma_mm: float
    """The operator's jogging error the meter assumes, mm per axis."""

    @property
    def meter_active(self) -> bool: ...

    def other_rotations(self) -> np.ndarray:
        """(N,3,3) ``R_world_flange`` of the touches recorded so far."""

    def preview(self, T_world_flange_m: npt.ArrayLike, *, min_angle_deg: float = 15.0) -> CandidateGain:
        """What a touch at ``T_world_flange_m`` (metres) would add (tcpcal's ``candidate_gain``)."""


@dataclass(frozen=True)
class RecordedPose:
    """One pose recorded at a wizard step.

    Attributes:
        T_world_flange_m: (4,4) flange pose in WORLD, metres.
        recorded_at: ISO 8601 UTC time of the recording.
    """

    T_world_flange_m: np.ndarray
    recorded_at: str

    def to_dict(self) -> dict[str, object]:
        return {"T_world_flange_m": self.T_world_flange_m.tolist(), "recorded_at": self.recorded_at}

    @classmethod
    def from_dict(cls, d: JsonRecord) -> "RecordedPose":
        return cls(check_pose_m(d["T_world_flange_m"]), str(d["recorded_at"]))


@dataclass(frozen=True)
class StepSpec:
    """What one step asks for (defined by each wizard).

    Attributes:
        role: what the recorded pose means: "touch" (tip on the reference tip), "minus_x" (tip
            on the tool's -X axis), "plus_y" (tip on the +Y axis), "plus_y_half" (tip in the +Y
            half of the tool XY plane), "parallel" (tool axes parallel to WORLD as prescribed).
        title: short name of the step ("Touch 3").
        instruction: one plain-words instruction: what to touch, from where.
        mount_tool_key: physical tool (ToolModel key) that must be mounted for this step, or
            None when any tool will do. The app does the swap.
    """

    role: str
    title: str
    instruction: str
    mount_tool_key: str | None = None


@dataclass(frozen=True)
class StepInfo:
    """Everything a view needs to render the current step.

    Attributes:
        index: 0-based index of the step.
        count: number of steps.
        heading: "Step k of n" (k is 1-based).
        title, instruction, role, mount_tool_key: as in :class:`StepSpec`.
        recorded: whether a pose is stored for this step.
    """

    index: int
    count: int
    heading: str
    title: str
    instruction: str
    role: str
    mount_tool_key: str | None
    recorded: bool


@dataclass(frozen=True, eq=False, kw_only=True)
class WizardResult:
    """The outcome of a finished wizard. Lengths in mm, angles in degrees.

    Attributes:
        wizard: "xyz4" | "reference" | "three-point" | "abc-world".
        method: calibration method as stored in ``tcpcal.Calibration.method``
            ("xyz4-lstsq", "reference", "three-point-1", "abc-world-5d", ...).
        tcp_mm: TCP X, Y, Z in FLANGE (calibrated by XYZ wizards, carried from the tool for
            orientation wizards).
        abc_deg: KUKA A, B, C of ``R_flange_tool`` when orientation is calibrated, else None.
        rotation: (3,3) ``R_flange_tool`` when orientation is calibrated, else None.
        tcp_result: the ``tcpcal`` TCP result (XYZ wizards) or None.
        orientation_result: the ``tcpcal`` orientation result or None.
        per_touch_error_mm: ``|e_i|`` per touch used (4P-3 residuals), empty for orientation.
        mean_error_mm, max_error_mm, rms_error_mm, ci95_mm: tcpcal figures or None.
        orthogonality_defect_deg: tcpcal figure (orientation) or None.
        displacements_mm: ``|Delta|`` lengths used by the orientation method.
        warnings: plain words, tcpcal's own first, then the wizard's.
        notes: standing advice that is not a warning about this result (e.g. that a small
            residual does not prove an accurate TCP).
        computed_at: ISO 8601 UTC.
    """

    wizard: str
    method: str
    tcp_mm: tuple[float, float, float]
    abc_deg: tuple[float, float, float] | None = None
    rotation: np.ndarray | None = None
    tcp_result: TcpResult | None = None
    orientation_result: OrientationResult | None = None
    per_touch_error_mm: tuple[float, ...] = ()
    mean_error_mm: float | None = None
    max_error_mm: float | None = None
    rms_error_mm: float | None = None
    ci95_mm: float | None = None
    orthogonality_defect_deg: float | None = None
    displacements_mm: tuple[float, ...] = ()
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    computed_at: str = field(default_factory=utc_now_iso)

    @property
    def orientation_calibrated(self) -> bool:
        """True when this result calibrates the TOOL orientation (A, B, C)."""
        return self.abc_deg is not None

    @property
    def figures(self) -> dict[str, float]:
        """Quality figures for ``tcpcal.Calibration.figures`` (only those that exist)."""
        out: dict[str, float] = {}
        for key in ("mean_error_mm", "max_error_mm", "rms_error_mm", "ci95_mm",
                    "orthogonality_defect_deg"):
            value = getattr(self, key)
            if value is not None:
                out[key] = float(value)
        for i, d in enumerate(self.displacements_mm, start=1):
            out[f"displacement_{i}_mm"] = float(d)
        if self.tcp_result is not None:
            out["n_touches"] = float(self.tcp_result.n_touches)
        return out

    def summary(self) -> dict[str, object]:
        """JSON-ready summary (used by the session record): method, frame, figures, warnings."""
        return {
            "wizard": self.wizard,
            "method": self.method,
            "tcp_mm": list(self.tcp_mm),
            "abc_deg": None if self.abc_deg is None else list(self.abc_deg),
            "per_touch_error_mm": list(self.per_touch_error_mm),
            "figures": self.figures,
            "warnings": list(self.warnings),
            "computed_at": self.computed_at,
        }


class _ComposedTexts(abc.ABC):
    """The language a :class:`Wizard` composes its per-instance texts in, and its refusals in
    words (the part of a wizard that knows languages; ``Wizard`` is the state machine)."""

    _tr: Translator
    _result: WizardResult | None
    _status: Status

    @property
    @abc.abstractmethod
    def finished_result(self) -> WizardResult | None: ...

    @property
    @abc.abstractmethod
    def blocked_reason(self) -> str | None: ...

    @abc.abstractmethod
    def _recompute(self) -> WizardResult | None: ...

    # ----- language of the texts it composes (module functions below) ----------------------
    @property
    def translator(self) -> Translator:
        """The language of the texts it composes: steps, :attr:`blocked_reason`, refusals, the
        result's warnings and notes (English until :meth:`set_translator`)."""
        return self._tr

    def set_translator(self, tr: Translator) -> None:
        """Compose the texts in ``tr``'s language from now on (the session's): the steps are
        composed when read; a result on hand is recomposed (:func:`recomposed_result`)."""
        if tr is not self._tr:
            self._tr = tr
            self._result = recomposed_result(self) or self._result

    def result_in(self, tr: Translator) -> WizardResult | None:
        """:attr:`finished_result` with its texts in ``tr``'s language (:func:`result_in`)."""
        return result_in(self, tr)

    def _refuse_blocked(self) -> None:
        """Raises WizardStateError naming :attr:`blocked_reason` when Record is disabled."""
        reason = self.blocked_reason
        if reason is not None:
            raise WizardStateError(self._tr.gettext("Cannot record now: {reason}").format(reason=reason))

    def _cancelled_refusal(self) -> WizardStateError:
        return WizardStateError(self._tr.gettext("The wizard was cancelled; resume it first."))

    def _next_refusal(self) -> WizardStateError:
        """Next refused: the wizard is not in progress (finished or cancelled)."""
        _ = self._tr.gettext
        if self._status == "complete":
            return WizardStateError(_("Next is not possible: the wizard is complete."))
        return WizardStateError(_("Next is not possible: the wizard is cancelled."))


class Wizard(_ComposedTexts):
    """Base state machine of a calibration wizard (see the module docstring for the life cycle).

    Subclasses define ``_step_specs()``, ``_compute()``, ``_params()``, ``_from_params()`` and
    ``to_tool()``, and describe themselves (``tcp_pendant.wizards.registry``) by the class
    attributes below and :meth:`start`; ``registry.register`` makes them a Calibrate method.

    Class attributes:
        kind: key in session records and the registry ("xyz4").
        title: the method's label in the menu ("XYZ 4-point").
        blurb: what the method calibrates and how, one or two sentences (markdown).
        calibrates: what the menu says Start will calibrate ("the TCP").
        rank: order in the menu.
        step_roles: every step role its steps use, each with its auto-touch role.
        options: the options it takes at start, with their choices.
        variants: (value, label) of its variants, switchable during the wizard (``set_variant``).
        needs_tool: "mounted" (calibrates the mounted tool, graded against its truth) or
            "library" (works on a library tool's data, made active at start).
        supports_add_point: "Add point" adds a touch (``add_point``).
        diversity_meter: the live pose-diversity meter is shown on touch steps (``preview``,
            ``other_rotations``, ``assumed_sigma_mm``).
        in_exercises: may be started in a classroom exercise (``workflow.hide_truth``); False
            for a method that measures the tool by itself (the beam sensor): it would hand the
            trainee the mystery tool's answer the exercise asks them to find by touching.
        saves_to_library: its result is a tool to save ("Save to tool library"); False for a
            check, which only measures the tool data it was given.
        controller_job: the name of the job the controller runs for it before it can finish
            (``calibrate.jobs.JOBS``: "spin_check", "beam_scan"), None when every step is
            recorded by hand and Finish only computes.
        result_view: how its result is shown (``calibrate.text.result_markdown`` and the result
            and scene views dispatch on it): "touches" (a TCP and/or orientation from recorded
            touches), "spin_check" (a check's rotations and verdict), "beam_scan" (a scan's
            events and the automatic-vs-manual lesson).
        result_extras: what more its result panel offers: "estimators" (the 4-point's
            estimator choice, outlier drop, estimator comparison and per-touch chart), "sphere"
            (the sphere fit drawn in 3D).
        math_view: the name of its worked equations ("The math" view, built by
            ``calibrate.math_view.MATH_VIEWS[name]``: "xyz4", "reference", "three_point",
            "abc_world", "tcp_zx", "beam", "spin_check"), None for a method without them.
    """

    kind: ClassVar[str]
    title: ClassVar[str]
    blurb: ClassVar[str] = ""
    calibrates: ClassVar[str] = N_("the TCP")
    rank: ClassVar[int] = 100
    step_roles: ClassVar[tuple[StepRole, ...]] = ()
    options: ClassVar[tuple[WizardOption, ...]] = ()
    variants: ClassVar[tuple[tuple[int | str, str], ...]] = ()
    needs_tool: ClassVar[Literal["mounted", "library"]] = "mounted"
    supports_add_point: ClassVar[bool] = False
    diversity_meter: ClassVar[bool] = False
    in_exercises: ClassVar[bool] = True
    saves_to_library: ClassVar[bool] = True
    controller_job: ClassVar[str | None] = None
    result_view: ClassVar[Literal["touches", "spin_check", "beam_scan"]] = "touches"
    result_extras: ClassVar[frozenset[str]] = frozenset()
    math_view: ClassVar[str | None] = None

    # ----- self-description (the registry, the menu and the workflow read these) -----------
    @classmethod
    def step_role(cls, name: str) -> StepRole:
        """The declared step role ``name`` (a ``WizardError`` if the class did not declare it)."""
        for role in cls.step_roles:
            if role.name == name:
                return role
        raise WizardError(f"The {cls.title} wizard declares no step role {name!r}.")

    def auto_role(self, step: StepInfo) -> AutoRole:
        """How auto-touch performs ``step`` (its declared role's; a variant may change it)."""
        return type(self).step_role(step.role).auto

    @classmethod
    def parse_options(cls, options: JsonRecord, *, tr: Translator = ENGLISH) -> JsonRecord:
        """The start options checked against :attr:`options` (and ``variant`` against
        :attr:`variants`); defaults filled in.

        Raises:
            WizardError: an unknown option, a value out of its choices, a missing required one
                (in ``tr``'s language).
        """
        _ = tr.gettext
        declared = {o.name: o for o in cls.options}
        allowed = set(declared) | ({"variant"} if cls.variants else set())
        unknown = sorted(set(options) - allowed)
        if unknown:
            raise WizardError(_("The {method} wizard takes no option {unknown}; it takes {allowed}.").format(
                method=_(cls.title), unknown=", ".join(unknown), allowed=", ".join(sorted(allowed)) or _("none")))
        out: dict[str, object] = {}
        try:
            for name, opt in declared.items():
                if name in options and options[name] is not None:
                    out[name] = opt.parse(options[name], tr=tr)
                elif opt.required:
                    raise OptionError(_("{option}: choose one before Start.").format(option=_(opt.label)))
                else:
                    out[name] = opt.default
        except OptionError as exc:
            raise WizardError(str(exc)) from None
        if cls.variants:
            values = [v for v, _label in cls.variants]
            variant = options.get("variant", values[0])
            if variant not in values:
                raise WizardError(_("The {method} variant is one of {values}, got {variant}.").format(
                    method=_(cls.title), values=values, variant=repr(variant)))
            out["variant"] = variant
        return out

    @classmethod
    def start(cls, ctx: StartContext, options: JsonRecord) -> WizardStart:
        """Build the wizard from checked ``options`` (:meth:`parse_options`)."""
        raise NotImplementedError(f"{cls.__name__} does not say how to start it.")

    # ----- capabilities the views ask for (defaults: none) ------------------------------
    @property
    def variant(self) -> int | str | None:
        """The variant in use (None when the wizard has none)."""
        return None

    def set_variant(self, variant: int | str) -> None:
        """Switch the variant (wizards with :attr:`variants` override this)."""
        raise WizardStateError(self._tr.gettext("The {method} wizard has no variants.").format(
            method=self._tr.gettext(self.title)))

    @property
    def can_add_point(self) -> bool:
        """"Add point" is possible now (only wizards with ``supports_add_point``)."""
        return False

    def solver_touch_steps(self) -> tuple[int, ...]:
        """The 0-based steps whose poses are the solver's touch rows, in row order (tcpcal's
        touch indices in an error map to these steps): every step of role "touch"."""
        return tuple(i for i, spec in enumerate(self._step_specs()) if spec.role == "touch")

    def add_point(self) -> None:
        """Add one touch step (only wizards with ``supports_add_point``)."""
        raise WizardStateError(self._tr.gettext("Add point is not part of the {method} wizard.").format(
            method=self._tr.gettext(self.title)))

    @property
    def meter_active(self) -> bool:
        """The pose-diversity meter applies now: a touch step of a wizard in progress that
        declares ``diversity_meter``."""
        return (self.diversity_meter and self._status == "in_progress"
                and self.step.role == "touch")

    @property
    def library_tool_name(self) -> str | None:
        """Name of the library tool this wizard works on (the name Save offers), or None."""
        return None

    def scene_target_T_world_tool_m(self, T_world_flange_m: np.ndarray) -> np.ndarray | None:
        """A target TOOL pose (4x4, metres, WORLD) the scene should draw now, or None."""
        return None

    def __init__(self) -> None:
        self._poses: dict[int, RecordedPose] = {}
        self._index = 0
        self._status: Status = "in_progress"
        self._result: WizardResult | None = None
        self._mounted_tool_key: str | None = None
        self._tool_labels: dict[str, str] = {}
        self._tr: Translator = ENGLISH
        self.started_at = utc_now_iso()

    def _recompute(self) -> WizardResult | None:
        """The result computed again from the recorded poses (None: not all recorded); a wizard
        whose result does not come from its poses overrides this."""
        if any(i not in self._poses for i in range(self.n_steps)):
            return None
        return self._compute([self._poses[i].T_world_flange_m for i in range(self.n_steps)])

    # ----- to be provided by each wizard --------------------------------------------------
    @abc.abstractmethod
    def _step_specs(self) -> list[StepSpec]:
        """The steps in order (may depend on the wizard's options)."""

    @abc.abstractmethod
    def _compute(self, poses: list[np.ndarray]) -> WizardResult:
        """Call tcpcal on the recorded poses (metres, in step order) and build the result."""

    @abc.abstractmethod
    def _params(self) -> dict[str, object]:
        """JSON-ready constructor options, for ``to_dict``."""

    @classmethod
    @abc.abstractmethod
    def _from_params(cls, params: JsonRecord) -> "Wizard":
        """Inverse of ``_params``."""

    # ----- steps --------------------------------------------------------------------------
    @property
    def status(self) -> Status:
        return self._status

    @property
    def n_steps(self) -> int:
        return len(self._step_specs())

    @property
    def step_index(self) -> int:
        """0-based index of the current step."""
        return self._index

    @property
    def steps(self) -> tuple[StepInfo, ...]:
        """All steps, e.g. for a step list in the view."""
        specs = self._step_specs()
        return tuple(self._info(i, s, len(specs)) for i, s in enumerate(specs))

    @property
    def step(self) -> StepInfo:
        """The current step."""
        specs = self._step_specs()
        return self._info(self._index, specs[self._index], len(specs))

    def _info(self, i: int, spec: StepSpec, n: int) -> StepInfo:
        heading = self._tr.gettext("Step {k} of {n}").format(k=i + 1, n=n)
        return StepInfo(index=i, count=n, heading=heading, title=spec.title,
                        instruction=spec.instruction, role=spec.role,
                        mount_tool_key=spec.mount_tool_key, recorded=i in self._poses)

    @property
    def progress(self) -> float:
        """Fraction 0..1 of the work done: recorded steps plus the result, over steps + 1."""
        n = self.n_steps
        done = sum(1 for i in range(n) if i in self._poses)
        return (done + (1 if self._status == "complete" else 0)) / (n + 1)

    @property
    def is_complete(self) -> bool:
        return self._status == "complete"

    @property
    def result(self) -> WizardResult | None:
        """The result once complete, else None."""
        return self._result if self._status == "complete" else None

    @property
    def finished_result(self) -> WizardResult | None:
        """The result of a finished wizard, also while it is cancelled (closed to resume later):
        what the session record stores and grades. None if it was never finished."""
        if self._status == "complete" or (
                self._status == "cancelled" and getattr(self, "_cancelled_from", None) == "complete"):
            return self._result
        return None

    @property
    def recorded_poses(self) -> dict[int, RecordedPose]:
        """Copy of the poses recorded so far, by 0-based step index."""
        return dict(self._poses)

    # ----- mounted tool (the app tells the wizard what is bolted on) ----------------------
    @property
    def mounted_tool_key(self) -> str | None:
        return self._mounted_tool_key

    def note_mounted_tool(self, key: str | None, labels: Mapping[str, str] | None = None) -> None:
        """Tell the wizard which physical tool is mounted (None: unknown, no check).

        Args:
            key: the mounted tool's key.
            labels: the tools' labels by key, for the words the trainee reads (kept until
                given again; a key without a label is shown as is).
        """
        self._mounted_tool_key = key
        if labels is not None:
            self._tool_labels = dict(labels)

    @property
    def blocked_reason(self) -> str | None:
        """Why Record is disabled right now, in words; None when it is enabled."""
        _ = self._tr.gettext
        if self._status == "cancelled":
            return _("The wizard was cancelled; resume it to continue.")
        if self._status == "complete":
            return _("The calibration is finished; go back to change a step.")
        spec = self._step_specs()[self._index]
        if (spec.mount_tool_key is not None and self._mounted_tool_key is not None
                and self._mounted_tool_key != spec.mount_tool_key):
            need = self._tool_labels.get(spec.mount_tool_key, spec.mount_tool_key)
            now = self._tool_labels.get(self._mounted_tool_key, self._mounted_tool_key)
            return _("Mount the {needed} first: the {mounted} is mounted now.").format(
                needed=shown_tool_label(need, self._tr, in_sentence=True),
                mounted=shown_tool_label(now, self._tr, in_sentence=True))
        return None

    @property
    def can_record(self) -> bool:
        """True only when the current step can be recorded (enables the Record button)."""
        return self.blocked_reason is None

    @property
    def can_back(self) -> bool:
        return self._status == "complete" or (self._status == "in_progress" and self._index > 0)

    @property
    def can_next(self) -> bool:
        """True when Next (or Finish, on the last step) is possible."""
        return self._status == "in_progress" and self._index in self._poses

    @property
    def on_last_step(self) -> bool:
        return self._index == self.n_steps - 1

    # ----- actions ------------------------------------------------------------------------
    def record(self, T_world_flange_m: npt.ArrayLike) -> StepInfo:
        """Store the flange pose (4x4, metres, WORLD) for the current step; overwrite any earlier.

        Returns:
            The current step, now marked recorded. The wizard does not move on by itself.

        Raises:
            WizardStateError: Record is disabled (see ``blocked_reason``).
            InvalidPoseError: the pose is not a rigid transform.
        """
        self._refuse_blocked()
        T = check_pose_m(T_world_flange_m)
        self._poses[self._index] = RecordedPose(T, utc_now_iso())
        return self.step

    def prefill(self, poses_m: Sequence[npt.ArrayLike]) -> StepInfo:
        """Record ``poses_m`` (4x4 flange poses in WORLD, metres) as the first steps of a wizard
        just started, then stand on the first step left to record (the last step when all are).
        Every pose is checked before any is stored.

        Raises:
            WizardStateError: the wizard is not fresh (in progress with nothing recorded), more
                poses than steps, or a step that cannot be recorded now (``blocked_reason``).
            InvalidPoseError: a pose is not a rigid transform (names which one).
        """
        _ = self._tr.gettext
        if self._status != "in_progress" or self._poses:
            raise WizardStateError(_("Only a wizard just started, with nothing recorded, takes touches recorded before."))
        if len(poses_m) > self.n_steps:
            raise WizardStateError(self._tr.ngettext(
                "{n} touches do not fit the {count} step of this wizard.",
                "{n} touches do not fit the {count} steps of this wizard.", self.n_steps,
            ).format(n=len(poses_m), count=self.n_steps))
        checked = [check_pose_m(T, what=f"flange pose of touch {i + 1}") for i, T in enumerate(poses_m)]
        self._refuse_blocked()
        now = utc_now_iso()
        self._poses = {i: RecordedPose(T, now) for i, T in enumerate(checked)}
        self._index = min(len(checked), self.n_steps - 1)
        return self.step

    def clear_step(self) -> None:
        """Forget the pose of the current step (only while in progress)."""
        if self._status != "in_progress":
            raise WizardStateError(self._tr.gettext("Only a wizard in progress can clear a step; go back first."))
        self._poses.pop(self._index, None)

    def next(self) -> StepInfo | WizardResult:
        """Go to the next step, or on the last step compute the result.

        Returns:
            The new current step, or the result when the wizard is now complete.

        Raises:
            WizardStateError: the current step is not recorded, or the wizard is not in progress.
            CalibrationFailedError: tcpcal rejected the poses (e.g. degenerate touches); the
                wizard stays on the last step so the user can re-record or add points.
        """
        if self._status != "in_progress":
            raise self._next_refusal()
        if self._index not in self._poses:
            raise WizardStateError(self._tr.gettext("Record step {k} before going on.").format(k=self._index + 1))
        if not self.on_last_step:
            self._index += 1
            return self.step
        return self.finish()

    def finish(self) -> WizardResult:
        """Compute the result from all steps (each must be recorded) and mark the wizard complete."""
        if self._status == "cancelled":
            raise self._cancelled_refusal()
        missing = [i + 1 for i in range(self.n_steps) if i not in self._poses]
        if missing:
            raise WizardStateError(self._tr.ngettext(
                "Step {steps} is not recorded yet.", "Steps {steps} are not recorded yet.", len(missing),
            ).format(steps=missing))
        poses = [self._poses[i].T_world_flange_m for i in range(self.n_steps)]
        try:
            result = self._compute(poses)
        except TcpcalError as exc:
            raise CalibrationFailedError(str(exc), exc) from exc
        self._result = result
        self._status = "complete"
        self._index = self.n_steps - 1
        return result

    def back(self) -> StepInfo:
        """Go back one step (from the result: back to the last step). Nothing is deleted."""
        if self._status == "complete":
            self._status = "in_progress"
            self._result = None
            return self.step
        if self._status != "in_progress" or self._index == 0:
            raise (WizardStateError(self._tr.gettext("There is no step before this one."))
                   if self._index == 0 else self._cancelled_refusal())
        self._index -= 1
        return self.step

    def go_to(self, index: int) -> StepInfo:
        """Jump to step ``index`` (0-based) if every step before it is recorded."""
        _ = self._tr.gettext
        if self._status == "cancelled":
            raise self._cancelled_refusal()
        if not 0 <= index < self.n_steps:
            raise WizardStateError(_("There is no step {k}; the wizard has {n}.").format(k=index + 1, n=self.n_steps))
        if any(i not in self._poses for i in range(index)):
            raise WizardStateError(_("Record the earlier steps first."))
        self._status = "in_progress"
        self._result = None
        self._index = index
        return self.step

    def cancel(self) -> None:
        """Leave the wizard. Nothing recorded is lost and nothing is saved anywhere: ``resume()``."""
        if self._status == "cancelled":
            return
        self._cancelled_from: Status = self._status
        self._status = "cancelled"

    def resume(self) -> StepInfo | WizardResult:
        """Return to where the user was before ``cancel()``."""
        if self._status != "cancelled":
            raise WizardStateError(self._tr.gettext("Only a cancelled wizard can be resumed."))
        self._status = getattr(self, "_cancelled_from", "in_progress")
        return self._result if self._status == "complete" and self._result is not None else self.step

    # ----- saving to the library ----------------------------------------------------------
    def _calibration(self, result: WizardResult, figures: Mapping[str, float]) -> Calibration:
        return Calibration(method=result.method, calibrated_at=result.computed_at,
                           figures=dict(figures))

    @abc.abstractmethod
    def to_tool(self, name: str) -> Tool:
        """The calibrated tool (for "Save to tool library"), with its Calibration record."""

    def _require_result(self) -> WizardResult:
        if self.result is None:
            raise WizardStateError(self._tr.gettext("Finish the wizard before saving the tool."))
        return self.result

    # ----- serialisation (resume, session record) -----------------------------------------
    def to_dict(self) -> dict[str, object]:
        """JSON-ready state: kind, options, recorded poses (metres), step, status."""
        status = self._status
        if status == "cancelled":
            status = getattr(self, "_cancelled_from", "in_progress")
        return {
            "kind": self.kind,
            "params": self._params(),
            "poses": {str(i): p.to_dict() for i, p in sorted(self._poses.items())},
            "step_index": self._index,
            "status": self._status,
            "resume_status": status,
            "started_at": self.started_at,
        }

    @classmethod
    def from_dict(cls, d: JsonRecord) -> "Wizard":
        """Rebuild a wizard from ``to_dict`` output; a complete wizard is recomputed with tcpcal.

        Called on the base class, dispatches on ``d["kind"]``.
        """
        from tcp_pendant.wizards.registry import WIZARD_TYPES  # local: the registry imports this module

        kind = d.get("kind")
        target = cls
        if cls is Wizard or getattr(cls, "kind", None) != kind:
            if kind not in WIZARD_TYPES:
                raise WizardError(f"Unknown wizard kind {kind!r}; expected one of {sorted(WIZARD_TYPES)}.")
            target = WIZARD_TYPES[kind]
        wiz = target._from_params(d.get("params", {}))
        wiz._load_state(d)
        return wiz

    def _load_state(self, d: JsonRecord) -> None:
        self._poses = {int(i): RecordedPose.from_dict(p) for i, p in d.get("poses", {}).items()}
        n = self.n_steps
        bad = [i for i in self._poses if not 0 <= i < n]
        if bad:
            raise WizardError(f"Recorded poses for steps {bad} do not exist in this wizard ({n} steps).")
        self._index = min(max(int(d.get("step_index", 0)), 0), n - 1)
        self.started_at = str(d.get("started_at", self.started_at))
        resume_status = d.get("resume_status", d.get("status", "in_progress"))
        if resume_status == "complete":
            self.finish()
        else:
            self._status = "in_progress"
        if d.get("status") == "cancelled":
            self.cancel()


def recomposed_result(wizard: _ComposedTexts) -> WizardResult | None:
    """``wizard``'s result on hand composed again in its current language: the same figures and
    ``computed_at`` (None: no result, or it cannot be recomputed)."""
    old = wizard._result
    if old is None:
        return None
    try:
        new = wizard._recompute()
    except (WizardError, TcpcalError):
        return None
    return None if new is None else dataclasses.replace(new, computed_at=old.computed_at)


_RESULTS_IN: "weakref.WeakKeyDictionary[_ComposedTexts, tuple[WizardResult, Translator, WizardResult]]" = \
    weakref.WeakKeyDictionary()


def result_in(wizard: _ComposedTexts, tr: Translator) -> WizardResult | None:
    """``wizard.finished_result`` with its texts in ``tr``'s language (a session record keeps
    English words whatever the trainee reads); kept until the result changes."""
    res = wizard.finished_result
    if res is None or tr is wizard._tr:
        return res
    cached = _RESULTS_IN.get(wizard)
    if cached is not None and cached[0] is res and cached[1] is tr:
        return cached[2]
    mine = wizard._tr
    wizard._tr = tr
    try:
        again = recomposed_result(wizard)
    finally:
        wizard._tr = mine
    out = res if again is None else again
    _RESULTS_IN[wizard] = (res, tr, out)
    return out


def mm3(v: Sequence[float] | np.ndarray) -> tuple[float, float, float]:
    """A 3-vector as a tuple of Python floats."""
    x, y, z = (float(t) for t in v)
    return (x, y, z)
