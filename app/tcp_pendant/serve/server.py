"""The pendant server: a viser server with one :class:`~tcp_pendant.session.Session` per
browser (default) or one shared session (``shared=True``, lecture demo).

Per-browser: ``on_client_connect`` builds a session in the client's own scene and GUI
(``client.scene`` / ``client.gui``) with its own :class:`VirtualController`;
``on_client_disconnect`` closes it and drops every reference (no leak: tested over 100
cycles). All sessions share the robot's pinocchio *model* (read-only) but each has its own
pinocchio *data*, so sessions never race in FK. The tool library is shared (one
``tcpcal.ToolLibrary``); a watcher thread notices when its file changes and every session
re-reads it (``SessionTools.reload_library``, on viser's event loop) so it sees tools saved by others.

Start tool: a per-browser session starts with no active tool (TCP = flange), whatever other
trainees activated or saved; the ``--shared`` session starts with the library's active slot
(the CLI's ``tcpcal tools activate``), see ``tcp_pendant.session``.
"""

from __future__ import annotations

import asyncio
import ipaddress
import logging
import socket
import threading
import time
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

import numpy as np

from tcpcal.library import ToolLibrary
from tcp_pendant.serve import client_script, origin_check
from tcp_pendant.calibrate import CalibrationWorkflow
from tcp_pendant.serve.addresses import network_urls
from tcp_pendant import job_pool
from tcp_pendant.serve.balance import Balance, BalanceFile
from tcp_pendant.job_pool import JobPool
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.class_views import ClassViews
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.classroom.library_rights import DEFAULT_LIBRARY_QUOTA
from tcp_pendant.controller import (
    BeamDevice,
    ControllerError,
    solve_ik,
    RobotKinematics,
    VirtualController,
    builtin_robots,
    builtin_tools,
    reference_tip_model,
)
from tcp_pendant.controller.placement import (
    MIN_TIP_HEIGHT_M,
    READY_HOVER_M,
    XYZ4_DIRECTIONS,
    best_hover_configuration,
    reachable_reference_tip,
    sampled_reach_m,
    unreachable_directions,
)
from tcp_pendant.controller.scenarios import Scenario
from tcp_pendant.controller.words import Words
from tcp_pendant.session import GuiTarget, Session
from tcp_pendant.translation import ENGLISH, N_, PSEUDO_LANGUAGE, Translator, languages, negotiate
from tcp_pendant.views import session_view_steps, viser_adapter
from tcp_pendant.views.dashboard import open_dashboard
from tcp_pendant.views.gui_util import target_of
from tcp_pendant.views.identity import IdentityPrompt
from tcp_pendant.views.presenter import PresenterView
from tcp_pendant.views.scene import overview_camera, overview_pose
from tcp_pendant.views.meshes import link_meshes, rigid_meshes

if TYPE_CHECKING:
    import viser

__all__ = ["AppConfig", "MIN_TIP_HEIGHT_M", "READY_HOVER_M", "PendantApp", "PortInUseError",
           "default_reference_tip_mm", "is_loopback", "ready_configuration", "resolve_robot",
           "tip_reach_warning"]

log = logging.getLogger(__name__)

ROBOT_LABELS = {"kr6": "KUKA KR 6 R900 sixx", "gp12": "Yaskawa GP12 class"}


@dataclass(frozen=True)
class AppConfig:
    """Start-up options (the CLI's; mm for the reference tip).

    Attributes:
        robot: "kr6", "gp12" or the path of a URDF or xacro file.
        package_paths: folders holding ROS packages (``--package-path``), searched before
            ``ROS_PACKAGE_PATH`` for the description's ``package://`` and ``$(find pkg)``.
        flange_link: link used as FLANGE (None: ``flange`` / last link of the longest chain).
        tool: mounted tool key ("pointer", "torch", "gripper").
        host, port: where to serve (port 0: a free port).
        tool_library: library file (None: the user's default, ``tcpcal`` platformdirs path).
        shared: one robot for every browser.
        reference_tip_mm: reference tip in WORLD, mm (None: :func:`default_reference_tip_mm`).
        library_poll_s: how often the library file is checked for changes by others.
        allow_origins: web origins (``scheme://host[:port]``) whose pages may connect besides
            the pendant's own address, e.g. a reverse proxy's (``tcp_pendant.serve.origin_check``).
        class_db: the class gradebook: an SQLite file, or a ``postgresql://`` URL (a ``str``) of
            the PostgreSQL database several servers share; None: no classroom (no name prompt,
            nothing recorded). The CLI passes its default path. Ignored with ``shared``.
        trainer_token: the token that opens the trainer view, 16 to 200 printable characters
            (None: a random one).
        exercise: None (free practice) or "mystery" (each trainee gets a mystery tool).
        exercise_seed: seed of the mystery tools (None: the class's secret seed, drawn once and
            kept in the gradebook; a number: that seed, for a reproducible demo).
        library_quota: in a class, the tool-library slots one trainee may hold (1..16; each
            trainee renames and deletes only their own, ``classroom.library_rights``).
        exercise_instructions, exercise_methods, exercise_min_touches: the exercise's brief at
            start (``ClassRoom``: instructions as plain text, the wizard kinds trainees may
            start, the fewest touches a Finish takes); None: the brief kept in the gradebook.
        scenario: the systematic error every session starts with (training;
            ``controller.scenarios``: "off", "bent_tool", "robot_accuracy", "moved_reference");
            the trainer changes it per pendant in the Calibrate tab.
        scenario_seed: seed of the scenario's errors (>= 0).
        presenter: every session starts in presenter mode (``views.presenter``; projector).
        beam_width_mm, beam_repeatability_mm, beam_crossed: the beam sensor beside the reference
            tip (``controller.beam_scan.BeamDevice``): beam diameter (0.05-5 mm, default 0.5),
            repeatability of an event per axis (0-1 mm, default 0.02), a second beam along
            WORLD Y crossing it.
        hide_truth: no pendant shows the truth (the TRUE triad, the error and the grade against
            the true TOOL frame), as in an exercise: a ``--shared`` projector in front of a class.
        language: the language every browser starts in (a code of ``translation.languages``;
            each browser may switch); "auto": the best of the browser's ``Accept-Language``,
            else English (:meth:`PendantApp.start_language`).
        seed: the one seed of every session's randomness (``Session.rng``: Auto-touch's operator
            error and directions, the beam's repeatability noise); session k of the server draws
            from ``(seed, k)``, so a seeded lesson or test replays the same way. None: fresh
            randomness.
        reuse_port: bind the port with ``SO_REUSEPORT`` (``views.viser_adapter.listen_reuse_port``):
            one of the server processes of ``tcp-pendant --workers N`` on the same port.
        balance_file: with ``reuse_port``, the record the ``--workers`` processes share so that
            each new connection goes to the process with the fewest browsers
            (``tcp_pendant.serve.balance``); None: the kernel's hash spreads them.
        presence_poll_s: the class's heartbeat period across server processes (seconds;
            ``ClassRoom.start``).
    """

    robot: str = "kr6"
    package_paths: tuple[Path, ...] = ()
    flange_link: str | None = None
    tool: str = "pointer"
    host: str = "127.0.0.1"
    port: int = 8080
    tool_library: Path | None = None
    shared: bool = False
    reference_tip_mm: tuple[float, float, float] | None = None
    library_poll_s: float = 1.0
    allow_origins: tuple[str, ...] = ()
    class_db: Path | str | None = field(default=None, repr=False)   # a URL may carry a password
    trainer_token: str | None = None
    exercise: str | None = None
    exercise_seed: int | None = None
    library_quota: int = DEFAULT_LIBRARY_QUOTA
    exercise_instructions: str | None = None
    exercise_methods: tuple[str, ...] | None = None
    exercise_min_touches: int | None = None
    scenario: str = "off"
    scenario_seed: int = 0
    presenter: bool = False
    beam_width_mm: float = 0.5
    beam_repeatability_mm: float = 0.02
    beam_crossed: bool = False
    seed: int | None = None
    hide_truth: bool = False
    reuse_port: bool = False
    balance_file: Path | None = None
    presence_poll_s: float = 1.0
    language: str = "auto"


class PortInUseError(OSError):
    """The port asked for is taken (another program, or another pendant, listens on it)."""

    def __init__(self, host: str, port: int) -> None:
        super().__init__(f"port {port} on {host} is already in use (another tcp-pendant?); stop that "
                         f"program, or choose another port: --port {port + 1 if port < 65535 else 8080}, "
                         "or --port 0 for any free port")
        self.host = host
        self.port = port


def is_loopback(host: str) -> bool:
    """True when ``host`` only accepts connections from this machine."""
    if host in ("localhost", "ip6-localhost"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        try:
            return all(ipaddress.ip_address(a[4][0]).is_loopback for a in socket.getaddrinfo(host, None))
        except (OSError, ValueError):
            return False


def resolve_robot(robot: str) -> Path:
    """Description file of "kr6", "gp12" or a path (``.urdf`` or ``.xacro``).

    Raises:
        ControllerError: unknown name or missing file.
    """
    robots = builtin_robots()
    if robot in robots:
        return robots[robot]
    path = Path(robot).expanduser()
    if path.suffix.lower() in (".urdf", ".xacro") or path.exists():
        if not path.is_file():
            raise ControllerError(f"Robot description not found: {path}. Give kr6, gp12 or the path of a "
                                  ".urdf or .xacro file.")
        return path.resolve()
    raise ControllerError(f"Unknown robot {robot!r}; use kr6, gp12 or the path of a .urdf or .xacro file.")


def _pointer_T_flange_tool() -> np.ndarray:
    return np.asarray(builtin_tools()["pointer"].T_flange_tool_true, dtype=float)


TIP_PLACEMENT_MM = (3.81, 1.28, -0.37)
"""How far the default reference tip of our robots stands from the round position below the
home flange (WORLD, mm), as a stand put down by hand does: no jog from the ready pose or a
wizard's suggested tilt is then a whole number of millimetres, so a touch needs the 1 mm and
0.1 mm increments, not the 10 mm one alone. Chosen so that, for each built-in tool on both
built-in robots, every WORLD offset from the ready pose and after the 30° B/C tilts is at
least 0.19 mm off a whole millimetre (tests/app/test_pendant_logic.py checks 0.1)."""


def default_reference_tip_mm(kinematics: RobotKinematics,
                             T_flange_tool: np.ndarray | None = None) -> tuple[float, float, float]:
    """Default reference tip (WORLD, mm), reachable from many directions.

    Our robots (a known home, ``RobotKinematics.known_home``): below the home flange position at
    half its height, the controller's own default (tested by the controller's auto-approach
    tests on both robots), moved by :data:`TIP_PLACEMENT_MM`: KR 6 (528.81, 1.28, 444.63); GP12
    (798.81, 1.28, 581.63); one whose home flange is lower than ``2 MIN_TIP_HEIGHT_M`` gets a
    point in front of it instead, at half its horizontal reach, a quarter of that reach high,
    moved alike.

    Any other robot: computed from its model, the first point in front of it that the mounted
    tool (``T_flange_tool``, default the pointer's true TCP) reaches from every direction of the
    XYZ 4-point's reach test (``controller.placement.reachable_reference_tip``).
    """
    if not kinematics.known_home:
        T = _pointer_T_flange_tool() if T_flange_tool is None else np.asarray(T_flange_tool, dtype=float)
        tip = reachable_reference_tip(kinematics, T) * 1000.0
        return (float(tip[0]), float(tip[1]), float(tip[2]))
    p = kinematics.T_world_flange(kinematics.home_rad)[:3, 3]
    if 0.5 * p[2] >= MIN_TIP_HEIGHT_M:
        tip = np.array([p[0], p[1], 0.5 * p[2]]) * 1000.0
    else:
        reach = sampled_reach_m(kinematics)
        tip = np.array([0.5 * reach, 0.0, max(MIN_TIP_HEIGHT_M, 0.25 * reach)]) * 1000.0
    tip = tip + np.asarray(TIP_PLACEMENT_MM)
    return (float(tip[0]), float(tip[1]), float(tip[2]))


def ready_configuration(kinematics: RobotKinematics, tip_world_m: np.ndarray | None = None) -> np.ndarray:
    """The session's start ("ready") pose, rad: the flange pointing straight down.

    Our robots (a known home): KUKA HOME has A5 = 0, a wrist singularity where Cartesian jogs
    along Y stop at once; with the 5th axis turned +-90 deg the flange points down, the wrist is
    well conditioned and the tool hangs over the reference tip, the natural start of a touch-up.

    Any other robot, given ``tip_world_m``: the best-conditioned configuration with the flange
    pointing down ``READY_HOVER_M`` above the tip (``controller.placement``:
    largest manipulability, clear of singularities and joint limits; for a 7-axis arm over its
    self-motion too). Without a tip, or when that hover pose has no solution: the 5th-axis turn
    above if it points the flange down, else HOME.
    """
    home = np.array(kinematics.home_rad, dtype=float)
    if not kinematics.known_home and tip_world_m is not None:
        q = best_hover_configuration(kinematics, np.asarray(tip_world_m, dtype=float))
        if q is not None:
            return q
    best, best_dot = home, 0.9
    if kinematics.n_joints >= 5 and kinematics.revolute[4]:
        for a5 in (np.pi / 2, -np.pi / 2):
            q = home.copy()
            q[4] = a5
            if not kinematics.lower_rad[4] <= a5 <= kinematics.upper_rad[4]:
                continue
            down = -float(kinematics.T_world_flange(q)[2, 2])      # flange Z . (-WORLD Z)
            if down > best_dot:
                best, best_dot = q, down
    if best is home and tip_world_m is not None:
        T = np.eye(4)
        T[:3, :3] = np.diag([1.0, -1.0, -1.0])                # flange Z along WORLD -Z
        T[:3, 3] = np.asarray(tip_world_m, dtype=float) + [0.0, 0.0, READY_HOVER_M]
        sol = solve_ik(kinematics, T, home)
        if sol.ok:
            return np.asarray(sol.q_rad, dtype=float)
    return best


def tip_reach_warning(kinematics: RobotKinematics, tip_world_m: np.ndarray, T_flange_tool: np.ndarray,
                      robot_label: str, tool_label: str) -> Words | None:
    """The start warning for a ``--reference-tip`` the mounted tool cannot reach from the XYZ
    4-point's directions (``placement.unreachable_directions``), or None when it can: English
    (stderr) that every pendant says again in its language (:class:`~tcp_pendant.controller.words.Words`)."""
    # a few seeds per direction (the hover pose's and home first): the start stays within about
    # a second when the tip is far out of reach
    reach = unreachable_directions(kinematics, tip_world_m, T_flange_tool, n_random_seeds=8, max_iterations=100)
    if reach.ok:
        return None
    tip = ", ".join(f"{v:.0f}" for v in np.asarray(tip_world_m) * 1000.0)
    what: list[Words] = []
    if not reach.hover_ok:
        what.append(Words(N_("the flange cannot hover pointing down {distance} mm above it"),
                          distance=f"{READY_HOVER_M * 1000:.0f}"))
    if reach.failed:
        failed = tuple(reach.failed)
        dirs = Words.by(lambda tr: ", ".join(tr.gettext("tilt {tilt}° azimuth {azimuth}°").format(
            tilt=f"{t:.0f}", azimuth=f"{a:.0f}") for t, a in failed))
        what.append(Words.by(lambda tr: tr.ngettext(
            "the {tool} cannot touch it from {n} of {count} test direction ({directions})",
            "the {tool} cannot touch it from {n} of {count} test directions ({directions})",
            len(XYZ4_DIRECTIONS)).format(tool=tool_label.lower(), n=len(failed), count=len(XYZ4_DIRECTIONS),
                                         directions=dirs.text(tr))))
    default = ",".join(f"{v:.0f}" for v in default_reference_tip_mm(kinematics, T_flange_tool))
    return Words(N_("the reference tip ({tip}) mm is out of reach of the {robot}: {what}. Auto-touch and "
                    "touch-ups there will fail; give a nearer --reference-tip, e.g. --reference-tip {default} "
                    "(this robot's default)."), tip=tip, robot=robot_label,
                 what=Words.by(lambda tr: "; ".join(w.text(tr) for w in what)), default=default)


class PendantApp:
    """The pendant server.

    Args:
        config: start-up options.

    Raises:
        ControllerError: bad robot, flange link, tool or reference tip.
    """

    def __init__(self, config: AppConfig) -> None:
        self.config = config
        urdf = resolve_robot(config.robot)
        self.kinematics = RobotKinematics.from_urdf(urdf, flange_link=config.flange_link,
                                                    package_paths=config.package_paths)
        self.robot_label = ROBOT_LABELS.get(config.robot, self.kinematics.description.name)
        tools = builtin_tools()
        if config.tool not in tools:
            raise ControllerError(f"Unknown tool {config.tool!r}; use one of {', '.join(tools)}.")
        self.tool = tools[config.tool]
        Scenario(config.scenario, seed=config.scenario_seed)  # type: ignore[arg-type]  # ControllerError: names the choices
        if config.language != "auto" and config.language not in languages(include_pseudo=True):
            raise ValueError(f"Unknown language {config.language!r}; use auto or one of "
                             f"{', '.join(languages())} ({PSEUDO_LANGUAGE}: the tests' pseudo-locale).")
        self.tip_warning: Words | None = None
        """:func:`tip_reach_warning` of a ``--reference-tip`` given (None: reachable, or the default)."""
        T_flange_tool = np.asarray(self.tool.T_flange_tool_true, dtype=float)
        tip = config.reference_tip_mm or default_reference_tip_mm(self.kinematics, T_flange_tool)
        tip_m = np.asarray(tip, dtype=float) / 1000.0
        if tip_m.shape != (3,) or not np.all(np.isfinite(tip_m)):
            raise ControllerError(f"Reference tip must be 3 finite numbers X,Y,Z in mm, got {tip!r}.")
        self.reference_tip_m = tip_m
        if config.reference_tip_mm is not None:
            self.tip_warning = tip_reach_warning(self.kinematics, tip_m, T_flange_tool, self.robot_label,
                                                 self.tool.label)
        self.beam_device = BeamDevice(width_m=config.beam_width_mm / 1000.0,      # ControllerError: says
                                      sigma_m=config.beam_repeatability_mm / 1000.0,  # the allowed range
                                      crossed=config.beam_crossed)
        self.ready_q_rad = ready_configuration(self.kinematics, tip_m)
        self.allow_origins = origin_check.parse_allow_origins(config.allow_origins)
        self.library = ToolLibrary(config.tool_library)
        self.robot_key = config.robot if config.robot in builtin_robots() else self.kinematics.description.name
        """The robot's name in session records: "kr6", "gp12" or the description's file name
        (without ``.urdf`` / ``.xacro``)."""
        if config.seed is not None and (isinstance(config.seed, bool) or not isinstance(config.seed, int)
                                        or config.seed < 0):
            raise ControllerError(f"The seed must be a whole number >= 0, got {config.seed!r}.")
        self._sessions_made = 0
        self.server: viser.ViserServer | None = None
        self.sessions: dict[int, Session] = {}
        self.shared_session: Session | None = None
        self._sessions_lock = threading.Lock()
        self._stop = threading.Event()
        self._watcher: threading.Thread | None = None
        self.jobs = JobPool()
        self.balance: Balance | None = None
        self._browsers = 0                  # websockets connected to this process (the balance's count)
        """The server's one pool of browser-triggered jobs, fair per session (``job_pool``)."""
        # warm the mesh caches so the first browser does not wait for STL parsing
        link_meshes(self.kinematics.description)
        for t in tools.values():
            rigid_meshes(t.urdf_path)
        rigid_meshes(reference_tip_model().urdf_path)
        self.gradebook: Gradebook | None = None
        self.classroom: ClassRoom | None = None
        if config.class_db is not None and not config.shared:
            self.gradebook = Gradebook(config.class_db)         # GradebookError: one clear message
            self.classroom = ClassRoom(self.gradebook, tools,
                                       trainer_token=config.trainer_token,
                                       exercise=config.exercise, exercise_seed=config.exercise_seed,
                                       library_quota=config.library_quota,
                                       instructions=config.exercise_instructions,
                                       allowed_methods=config.exercise_methods,
                                       min_touches=config.exercise_min_touches,
                                       hand_to_loop=self._hand_to_loop, call_later=self._call_later,
                                       presence_poll_s=config.presence_poll_s,
                                       views=ClassViews(welcome=IdentityPrompt, dashboard=open_dashboard,
                                                        client_address=viser_adapter.client_address))

    @property
    def warnings(self) -> list[str]:
        """What the start says on stderr (the CLI prints each as a ``WARNING:`` line) and every
        pendant shows (:meth:`start_notices`): each visual mesh not found (which, why, what to do,
        how its link is drawn instead), a ``--reference-tip`` out of reach."""
        return self.kinematics.description.mesh_warnings() + ([self.tip_warning] if self.tip_warning else [])

    # ------------------------------------------------------------ sessions
    def new_controller(self) -> VirtualController:
        """A controller with its own pinocchio data (the model is shared, read-only)."""
        c = VirtualController(self.kinematics.own_copy(), tool=self.tool,
                              reference_tip_world_m=self.reference_tip_m)
        c.set_beam_device(self.beam_device)
        c.set_q(self.ready_q_rad)
        c.set_rest_configuration(self.ready_q_rad)
        return c

    def session_rng(self) -> np.random.Generator:
        """The next session's random generator: from ``(seed, k)`` for the server's k-th session
        when a seed was given (``AppConfig.seed``), else fresh."""
        k, self._sessions_made = self._sessions_made, self._sessions_made + 1
        seed = self.config.seed
        return np.random.default_rng() if seed is None else np.random.default_rng([int(seed), k])

    def make_session(self, client: viser.ClientHandle | None, target: GuiTarget | None = None, *,
                     shared: bool = False) -> Session:
        """Build a session drawing into ``target`` (default: ``client``). A per-browser session
        starts with no active tool (TCP = flange); the shared one (``shared``) with the
        library's active tool (module docstring)."""
        *_, session = self.session_steps(client, target, shared=shared)
        assert session is not None
        return session

    def start_language(self, client: viser.ClientHandle | None) -> str:
        """The language a session starts in: the language the trainer pushed to the class
        (``ClassRoom.class_language``), else ``--language`` when it names one; with ``auto`` (the
        default) the best of the browser's ``Accept-Language`` the pendant offers
        (``translation.negotiate``), else English (the ``--shared`` session: English)."""
        pushed = None if self.classroom is None or client is None else self.classroom.class_language
        if pushed is not None:
            return pushed
        if self.config.language != "auto":
            return self.config.language
        return negotiate(None if client is None else viser_adapter.accept_language(client))

    def session_steps(self, client: viser.ClientHandle | None, target: GuiTarget | None = None, *,
                      shared: bool = False) -> Generator[Session | None, None, None]:
        """:meth:`make_session` step by step: yields None after each step (a view, a few to a few
        tens of ms) and the finished session last (``on_client_connect`` awaits between the
        steps on viser's event loop). Closing the generator early closes the half-built session.
        """
        c = self.new_controller()
        rng = self.session_rng()
        workflow = CalibrationWorkflow(c, self.library, robot=self.robot_key, rng=rng)
        session = Session(c, self.library, workflow, client=client, target=target, ready_q_rad=self.ready_q_rad,
                          shared=shared, rng=rng, jobs=self.jobs, language=self.start_language(client))
        session.tools.reload_library()
        if shared:
            try:
                slot = self.library.active_slot()
            except Exception:  # an unreadable library must not keep the pendant from starting
                log.exception("tool library unreadable")
                slot = None
            tool = None if slot is None else session.tools.library_tools.get(slot)
            if tool is not None:
                session.tools.set_active_data(tool, slot)
        if self.config.scenario != "off":
            session.set_scenario(self.config.scenario, self.config.scenario_seed)
        if self.config.hide_truth:
            session.wizard_commands.set_hide_truth(True, always=True)
        try:
            for _ in session_view_steps(session, title=f"TCP Pendant · {self.robot_label}"):
                yield None
            with session.lock, target_of(session).atomic():    # "Presenter mode", above the tabs
                session.views["presenter"] = PresenterView(session, on=self.config.presenter)
        except GeneratorExit:
            session.close()
            raise
        if self.classroom is not None and not shared:
            self.classroom.attach(session)
        yield session

    def close_session(self, client: viser.ClientHandle) -> None:
        """``on_client_disconnect``: close and forget the browser's session."""
        with self._sessions_lock:
            session = self.sessions.pop(client.client_id, None)
        if session is not None:
            session.close()

    async def _on_connect(self, client: viser.ClientHandle) -> None:
        """``on_client_connect``, on viser's event loop (every push from the loop's thread): the
        browser's session is built a view at a time, other browsers' callbacks run in between;
        a browser that left meanwhile gets nothing registered."""
        self._count_browser(+1)
        if self.config.shared:
            if self.shared_session is not None:
                try:
                    overview_camera(client, self.reference_tip_m)
                    self.show_start_notices(client)
                except Exception:
                    log.debug("camera of a leaving client", exc_info=True)
            return
        steps = self.session_steps(client)
        session: Session | None = None
        try:
            for session in steps:
                if session is not None:
                    break
                await asyncio.sleep(0)
                if self.server is None or client.client_id not in self.server.get_clients():
                    steps.close()                       # left while its session was built
                    return
        except Exception:
            log.exception("building the session of client %s failed", getattr(client, "client_id", "?"))
            return
        if session is None:
            return
        with self._sessions_lock:
            self.sessions[client.client_id] = session
        try:
            overview_camera(client, self.reference_tip_m)
            self.show_start_notices(client)
        except Exception:
            log.debug("camera of a leaving client", exc_info=True)

    def start_notices(self, *, tr: Translator = ENGLISH) -> list[tuple[str, str]]:
        """(title, body) of the notifications every browser gets when it connects: the start
        warnings (:attr:`warnings`) in plain text (viser shows them as text), in ``tr``'s
        language (the reach check's words as it composed them)."""
        out = []
        missing = [m for m in self.kinematics.description.missing_meshes if m.kind == "visual"]
        if missing:
            names = ", ".join(Path(m.uri).name for m in missing[:6]) + (" ..." if len(missing) > 6 else "")
            n = len(missing)
            out.append((tr.gettext("Robot meshes not found"),
                        tr.ngettext("{n} mesh of the robot was not found ({names}): those links are drawn "
                                    "from their collision geometry or as simple shapes. The terminal that started "
                                    "the pendant says where each was looked for (--package-path, ROS_PACKAGE_PATH).",
                                    "{n} meshes of the robot were not found ({names}): those links are drawn "
                                    "from their collision geometry or as simple shapes. The terminal that started "
                                    "the pendant says where each was looked for (--package-path, ROS_PACKAGE_PATH).",
                                    n).format(n=n, names=names)))
        if self.tip_warning is not None:
            out.append((tr.gettext("Reference tip out of reach"), self.tip_warning.text(tr)))
        return out

    def show_start_notices(self, client: viser.ClientHandle) -> None:
        """Show :meth:`start_notices` in ``client``'s browser (they stay until closed), in its
        session's language."""
        session = self.sessions.get(client.client_id)
        for title, body in self.start_notices(tr=ENGLISH if session is None else session.translator):
            client.add_notification(title, body, color="yellow", with_close_button=True,
                                    auto_close_seconds=None)

    def _count_browser(self, delta: int) -> None:
        """One browser more or fewer on this process: the ``--workers`` balance hears of it."""
        self._browsers = max(0, self._browsers + delta)
        if self.balance is not None:
            try:
                self.balance.sessions(self._browsers)
            except OSError:
                log.exception("the connection balance of the server processes could not be updated")

    async def _on_disconnect(self, client: viser.ClientHandle) -> None:
        """``on_client_disconnect``, on viser's event loop like every other callback."""
        self._count_browser(-1)
        if not self.config.shared:
            self.close_session(client)

    def all_sessions(self) -> list[Session]:
        """Every open session (the shared one in shared mode)."""
        with self._sessions_lock:
            out = list(self.sessions.values())
        return out + ([self.shared_session] if self.shared_session is not None else [])

    # ------------------------------------------------------------ library watcher
    def _library_stamp(self) -> tuple[int, int] | None:
        try:
            st = Path(self.library.path).stat()
            return (st.st_mtime_ns, st.st_size)
        except OSError:
            return None

    def _watch_library(self) -> None:
        last = self._library_stamp()
        while not self._stop.wait(self.config.library_poll_s):
            stamp = self._library_stamp()
            if stamp == last:
                continue
            last = stamp
            self._hand_to_loop(self.library_changed)

    def _hand_to_loop(self, fn: Callable[[], object]) -> None:
        """Run ``fn()`` on viser's event loop, where every GUI callback runs (from the library
        watcher: its reload pushes messages, which only the loop's thread may do)."""
        server = self.server
        if server is None:
            return
        try:
            server.get_event_loop().call_soon_threadsafe(fn)
        except RuntimeError:                     # the loop is closed: the server is stopping
            log.debug("library reload dropped: server stopped")

    def _call_later(self, delay_s: float, fn: Callable[[], object]) -> None:
        """Run ``fn()`` on viser's event loop after ``delay_s`` seconds (the dashboards' throttle
        and clock tick; from any thread)."""
        server = self.server
        if server is None:
            raise RuntimeError("the server is not running")
        loop = server.get_event_loop()
        loop.call_soon_threadsafe(loop.call_later, max(0.0, delay_s), fn)

    def library_changed(self) -> None:
        """Every session re-reads the library (on viser's event loop: the watcher hands it
        over); their views re-render on the change signal."""
        for s in self.all_sessions():
            s.loop.guard(s.tools.reload_library)()

    # ------------------------------------------------------------ life cycle
    def start(self) -> str:
        """Start serving; returns the URL."""
        host = self.config.host
        origin_check.enable()               # foreign web pages' websockets are refused (403)
        viser_adapter.install()             # every browser message checked before viser's handlers
        client_script.script_asset()        # the page's own script (keys, name, trainer URL): packaged?
        job_pool.favour_the_event_loop()    # a busy job thread hands the GIL back to the loop within 1 ms
        with origin_check.starting():       # requests get 503 "starting" until mark_ready
            self._start_serving(host)
        return self.url

    def _start_serving(self, host: str) -> None:
        """The viser server, its policies, page script and session handlers; then ready."""
        import viser

        if self.config.reuse_port:              # one port, several server processes (--workers)
            if self.config.balance_file is not None:
                self.balance = Balance(BalanceFile(self.config.balance_file))
                viser_adapter.listen_reuse_port(self.balance.listening, self.balance.started)
            else:
                viser_adapter.listen_reuse_port()
        self.server = viser.ViserServer(host=host, port=self.config.port, verbose=False)
        origin_check.allow(self.port, self.allow_origins,
                           origin_check.served_hosts(host, self.network_urls, self.allow_origins))
        origin_check.set_http_layer(self.port, client_script.serve)
        if self.config.port != 0 and self.port != self.config.port:
            # viser silently moves on to the next free port; the class was told this one
            origin_check.forget(self.port)
            self.server.stop()
            self.server = None
            raise PortInUseError(host, self.config.port)
        self.server.gui.configure_theme(control_width="large", dark_mode=False, show_logo=False,
                                        show_share_button=False)
        self.server.gui.main_panel.dock_right()
        position, look_at = overview_pose(self.reference_tip_m)
        self.server.initial_camera.position = position
        self.server.initial_camera.look_at = look_at
        if self.config.shared:
            self.shared_session = self.make_session(None, target=self.server, shared=True)
        self.server.on_client_connect(self._on_connect)
        self.server.on_client_disconnect(self._on_disconnect)
        self._watcher = threading.Thread(target=self._watch_library, name="library-watcher", daemon=True)
        self._watcher.start()
        if self.classroom is not None:
            self.classroom.start()          # presence heartbeat, the other processes' pushes
        origin_check.mark_ready(self.port)  # until now every request got 503 "starting"

    @property
    def trainer_url(self) -> str | None:
        """The trainer view's address, ``URL/?trainer=TOKEN`` (None without a classroom): the
        page's script (``client_script``) types the token into "Trainer token" and drops it
        from the address bar; the token is percent-encoded (``--trainer-token`` may hold any
        printable character)."""
        if self.classroom is None or self.classroom.trainer_token is None:
            return None                       # the class's kept token: only its hash is known
        return f"{self.url}/?trainer={quote(self.classroom.trainer_token, safe='')}"

    @property
    def port(self) -> int:
        """The port actually served."""
        return int(self.server.get_port()) if self.server is not None else self.config.port

    @property
    def network_urls(self) -> list[str]:
        """The URLs other machines can open (``addresses.network_urls``): for ``--host 0.0.0.0``
        the host name and every usable address; empty when serving on loopback."""
        if is_loopback(self.config.host):
            return []
        return network_urls(self.config.host, self.port)

    @property
    def url(self) -> str:
        """``http://host:port`` (for a wildcard host: ``127.0.0.1``, this machine's URL)."""
        host = self.config.host
        shown = "127.0.0.1" if host in ("0.0.0.0", "") else "::1" if host == "::" else host
        if ":" in shown and not shown.startswith("["):
            shown = f"[{shown}]"
        return f"http://{shown}:{self.port}"

    def stop(self) -> None:
        """Stop the watcher, close every session and the server."""
        self._stop.set()
        for s in self.all_sessions():
            s.close()
        with self._sessions_lock:
            self.sessions.clear()
        self.shared_session = None
        if self.server is not None:
            origin_check.forget(self.port)
            self.server.stop()
        self.jobs.shutdown(wait=False)
        if self.classroom is not None:
            self.classroom.close()          # frees the names this process held
        if self.gradebook is not None:
            self.gradebook.close()

    def serve_forever(self, poll_s: float = 0.5, alive: Callable[[], bool] | None = None) -> None:
        """Block until interrupted (Ctrl-C) or, with ``alive``, until it returns False (a
        worker of ``--workers``: the first process is gone), then stop."""
        try:
            while not self._stop.is_set() and (alive is None or alive()):
                time.sleep(poll_s)
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()


def parse_xyz_mm(text: str | Sequence[float]) -> tuple[float, float, float]:
    """``"X,Y,Z"`` in mm -> tuple (finite numbers).

    Raises:
        ControllerError: not three finite numbers.
    """
    parts = text.replace(";", ",").split(",") if isinstance(text, str) else list(text)
    try:
        vals = tuple(float(p) for p in parts)
    except (TypeError, ValueError):
        raise ControllerError(f"Expected X,Y,Z in mm (three numbers separated by commas), got {text!r}.") from None
    if len(vals) != 3 or not all(np.isfinite(vals)):
        raise ControllerError(f"Expected X,Y,Z in mm (three finite numbers separated by commas), got {text!r}.")
    return vals
