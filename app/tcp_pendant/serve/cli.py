"""``tcp-pendant``: start the teach-pendant web app.

Examples::

    tcp-pendant                                  # KR 6, pointer, http://127.0.0.1:8080
    tcp-pendant --robot gp12 --tool torch --port 8090
    tcp-pendant --robot /path/ur5.urdf --flange-link tool0
    tcp-pendant --robot ~/ws/src/kuka_experimental/kuka_kr16_support/urdf/kr16_2.xacro \
        --package-path ~/ws/src/kuka_experimental        # a ROS-Industrial description
    tcp-pendant --host 0.0.0.0 --shared          # classroom demo: one robot for everybody
    tcp-pendant --shared --presenter             # the lecture on a projector: large readout
    tcp-pendant --host 0.0.0.0 --class           # a class: names, gradebook, trainer view
    tcp-pendant --host 0.0.0.0 --class --workers 2   # a large class on both cores (one port)
    tcp-pendant --host 0.0.0.0 --exercise mystery --exercise-seed 7   # a class with mystery tools
    tcp-pendant grades --csv > grades.csv        # the class gradebook (see classroom.grades_cli)
    tcp-pendant poses import touch.ls --robot kr6 > POSES.csv   # joint points by the robot's FK
    tcp-pendant --scenario bent-tool --scenario-seed 3   # training: a systematic error to find
"""

from __future__ import annotations

import argparse
import gc
import logging
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from tcp_pendant.classroom.gradebook_db import class_db_target, url_has_password
from tcp_pendant.serve.token_notice import class_lines, token_source
from tcp_pendant.translation import languages

if TYPE_CHECKING:                       # the server is imported in main() only (no pinocchio for --help)
    from tcp_pendant.serve.server import PendantApp
    from tcp_pendant.serve.workers import Workers

__all__ = ["SCENARIO_CHOICES", "build_parser", "main", "network_warning", "ready_urls"]

SCENARIO_CHOICES = ("off", "bent-tool", "robot-accuracy", "moved-reference")
"""``--scenario`` names: ``controller.scenarios.SCENARIO_KINDS`` with hyphens (no pinocchio import
for ``--help``)."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (options in mm where they are lengths): the robot, the server and
    what every pendant shows, the class, the training (scenarios, beam sensor, seed), then the
    processes; ``--help`` lists them in that order."""
    p = argparse.ArgumentParser(
        prog="tcp-pendant",
        description="Teach-pendant web app for TCP / TOOL frame calibration training. "
                    "Each browser gets its own virtual robot unless --shared is given.")
    _add_robot_options(p)
    _add_server_options(p)
    _add_class_options(p)
    _add_training_options(p)
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="N server processes on the one port (SO_REUSEPORT: the system spreads the browsers "
                        "over them), to use N cores for a large class (default 1; up to 32; not with "
                        "--shared); a class shares names, pushed settings and the trainer's table through "
                        "the gradebook")
    p.add_argument("--verbose", action="store_true", help="log debugging information")
    return p


def _add_robot_options(p: argparse.ArgumentParser) -> None:
    """The robot and the tool mounted at start."""
    p.add_argument("--robot", default="kr6",
                   help="kr6 (KUKA KR 6 R900 sixx, default), gp12 (Yaskawa GP12 class), PATH.urdf or "
                        "PATH.xacro (a ROS description: package:// meshes are found through --package-path "
                        "and ROS_PACKAGE_PATH)")
    p.add_argument("--package-path", action="append", default=[], type=Path, metavar="DIR",
                   help="a folder holding ROS packages (or a package itself), searched for the robot's "
                        "package:// meshes and xacro's $(find pkg) before ROS_PACKAGE_PATH (repeatable)")
    p.add_argument("--flange-link", default=None,
                   help="link used as FLANGE (default: 'flange', else the last link of the longest chain)")
    p.add_argument("--tool", default="pointer", choices=("pointer", "torch", "gripper"),
                   help="physical tool mounted at start (default: pointer)")


def _add_server_options(p: argparse.ArgumentParser) -> None:
    """Where the server listens, the tool library, and what every pendant shows."""
    p.add_argument("--host", default="127.0.0.1",
                   help="address to bind (default 127.0.0.1; anything else lets the network connect)")
    p.add_argument("--port", type=int, default=8080,
                   help="port (default 8080; 0: any free port; a port in use is refused, exit 2)")
    p.add_argument("--tool-library", type=Path, default=None,
                   help="tool library JSON file (default: the user's data directory)")
    p.add_argument("--shared", action="store_true",
                   help="one robot that every browser sees and drives (lecture demo)")
    p.add_argument("--presenter", action="store_true",
                   help="start in presenter mode (projector: 32 px readout, the wizard's step list, a "
                        "large error chart, a narrower panel); each pendant can switch it in its GUI")
    p.add_argument("--hide-truth", action="store_true",
                   help="show no truth (the TRUE triad, the error and grade against the true TOOL frame) "
                        "on any pendant: for a projector in front of a class that calibrates the same tool")
    p.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                   help="also accept browsers on pages from ORIGIN (scheme://host[:port]; repeatable or "
                        "comma-separated), e.g. a reverse proxy's address; pages from any other web "
                        "site are refused")
    p.add_argument("--reference-tip", default=None, metavar="X,Y,Z",
                   help="reference tip position in WORLD, mm (default: below the home flange at half "
                        "its height on kr6 and gp12, e.g. 525,0,445 on the KR 6; for another robot a point "
                        "in front of it that the tool reaches from the XYZ 4-point's directions); a tip out "
                        "of reach is warned about at start")


def _add_class_options(p: argparse.ArgumentParser) -> None:
    """A class: the gradebook, the trainer token, the exercise and its brief, library quotas."""
    p.add_argument("--class", dest="classroom", action="store_true",
                   help="run a class: each browser gives a name, every calibration is stored in the class "
                        "gradebook, and a trainer view (token) shows the class; implied by --class-db, "
                        "--exercise (and its --exercise-* options) and --trainer-token")
    p.add_argument("--class-db", type=class_db_target, default=None, metavar="PATH|URL",
                   help="the class gradebook, an SQLite file every trainee's calibrations are stored in "
                        "(default with --class: the user's data directory, class.sqlite3), or a "
                        "postgresql://USER@HOST:PORT/DATABASE URL: one PostgreSQL database that servers on "
                        "several machines share (needs psycopg: pip install 'tcp-pendant[postgres]')")
    p.add_argument("--trainer-token", default=None, metavar="TOKEN",
                   help="the token that opens the trainer view, 16 to 200 printable characters (default: "
                        "$TCP_PENDANT_TRAINER_TOKEN, else a random one, kept in a file named at start); a token given "
                        "here shows in the process list: prefer --trainer-token-file")
    p.add_argument("--trainer-token-file", type=Path, default=None, metavar="PATH",
                   help="read the trainer token from the first line of PATH (like --trainer-token, "
                        "but not shown in the process list)")
    p.add_argument("--print-token", action="store_true", help="print the whole trainer token and the trainer "
                   "address at start (default: its first 4 characters and where to read it)")
    p.add_argument("--exercise", default=None, choices=("mystery",),
                   help="start an exercise: mystery = each trainee calibrates a tool of their own whose "
                        "true TCP and orientation only the gradebook knows")
    p.add_argument("--exercise-seed", type=int, default=None, metavar="N",
                   help="seed of the mystery tools, for a reproducible demo (default: the class's own "
                        "secret seed, drawn at random once and kept in the gradebook)")
    p.add_argument("--library-quota", type=int, default=None, metavar="N",
                   help="in a class: the tool-library slots one trainee may hold (1..16, default 3); each "
                        "trainee renames and deletes only the slots they saved, the trainer every slot")
    p.add_argument("--exercise-instructions", default=None, metavar="TEXT",
                   help="the exercise's instructions, shown in a banner at the top of every trainee's "
                        "panel (plain text, at most 2000 characters; default: the instructions kept in "
                        "the gradebook, else none)")
    p.add_argument("--exercise-methods", default=None, metavar="IDS",
                   help="the calibration methods trainees may start, comma-separated wizard ids (xyz4, "
                        "reference, tcp-zx, three-point, abc-world, tcp-check, beam); the others are not "
                        "offered (default: the methods kept in the gradebook, else all)")
    p.add_argument("--exercise-min-touches", type=int, default=None, metavar="N",
                   help="the fewest touches a Finish takes (0 to 20) in the methods whose touch count the "
                        "trainee chooses (XYZ 4-point, TCP & Z, X); default: the minimum kept in the "
                        "gradebook, else none")


def _add_training_options(p: argparse.ArgumentParser) -> None:
    """Training: the scenario's systematic error, the beam sensor, one seed for the randomness."""
    p.add_argument("--scenario", default="off", choices=SCENARIO_CHOICES, metavar="NAME",
                   help="training: a systematic error every pendant starts with (off, bent-tool, "
                        "robot-accuracy, moved-reference; default off); the trainer can change it in the "
                        "Calibrate tab")
    p.add_argument("--scenario-seed", type=int, default=0, metavar="N",
                   help="seed that draws the scenario's errors (default 0; >= 0)")
    p.add_argument("--beam-width", type=float, default=0.5, metavar="MM",
                   help="the beam sensor's beam diameter, mm (0.05 to 5; default 0.5)")
    p.add_argument("--beam-repeatability", type=float, default=0.02, metavar="MM",
                   help="the beam sensor's repeatability per axis of a recorded event, mm (0 to 1; "
                        "default 0.02)")
    p.add_argument("--beam-crossed", action="store_true",
                   help="a second beam along WORLD Y crosses the first (crossed beams, as on TRACC-type "
                        "devices)")
    p.add_argument("--language", default="auto", choices=("auto",) + languages(include_pseudo=True),
                   metavar="LANG",
                   help="the language every browser starts in: " + ", ".join(languages()) + "; default auto: "
                        "each browser's own (its Accept-Language), else English. Each trainee can switch "
                        "with the Language selector in the Jog tab's View folder (docs/languages.md)")
    p.add_argument("--seed", type=int, default=None, metavar="N",
                   help="one seed for every pendant's randomness (Auto-touch's operator error and "
                        "directions, the beam sensor's noise): a seeded lesson replays the same way "
                        "(default: fresh randomness; >= 0)")


def network_warning(host: str) -> str | None:
    """The warning printed when ``host`` lets other machines connect (None for loopback)."""
    from tcp_pendant.serve.server import is_loopback

    if is_loopback(host):
        return None
    return (f"WARNING: listening on {host}: anyone on the network who can reach this machine "
            "can open the pendant and save tools to the library. Use --host 127.0.0.1 to keep it local.")


def ready_urls(local_url: str, network: Sequence[str], host: str) -> str:
    """The URLs of the ready line: on loopback ``local_url``; listening on the network, the URLs
    trainees can open (host name and addresses), then this machine's own URL.

    Args:
        local_url: the URL that works on this machine (``PendantApp.url``).
        network: ``PendantApp.network_urls`` (empty on loopback, or when no address was found).
        host: the ``--host`` given.
    """
    from tcp_pendant.serve.server import is_loopback

    if is_loopback(host) or list(network) == [local_url]:
        return local_url
    if not network:
        return (f"{local_url}\n  no network address of this machine was found: trainees cannot connect; "
                "check the network connection")
    return f"{network[0]}\n  trainees open: {'  '.join(network)}   (on this machine: {local_url})"


def main(argv: Sequence[str] | None = None) -> int:
    """Parse the options, start the server, print the URL and serve until Ctrl-C.

    Returns:
        0 after a clean stop; 2 for bad options (with the message on stderr); 130 when
        interrupted (Ctrl-C) before the server was ready.
    """
    args_list = list(sys.argv[1:] if argv is None else argv)
    if args_list[:1] == ["grades"]:
        from tcp_pendant.classroom.grades_cli import main as grades_main

        return grades_main(args_list[1:])
    if args_list[:2] == ["poses", "import"]:
        from tcp_pendant.serve.poses_import_cli import main as poses_import_main

        return poses_import_main(args_list[2:])
    try:
        return _main(args_list)
    except KeyboardInterrupt:               # Ctrl-C while loading the robot or starting
        print("tcp-pendant: interrupted", file=sys.stderr)
        return 130


class _Refused(Exception):
    """Options or a start that cannot go on: the message, printed after "tcp-pendant: error: "
    (exit 2)."""


def _main(argv: Sequence[str] | None) -> int:
    t0 = time.perf_counter()
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.DEBUG if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        worker = _check_processes(args)
        trainer_token, class_db = _check_class(args, worker)
        balance_file = _balance_file(args.workers, worker)
        app = _make_app(args, trainer_token, class_db, balance_file, worker)
        url = _start(app, args, balance_file, worker)
    except _Refused as exc:
        print(f"tcp-pendant: error: {exc}", file=sys.stderr)
        return 2
    set_apart_startup_objects()
    if worker is not None:
        return _serve_as_worker(app, worker[2])
    try:
        workers = _start_workers(app, args, argv, balance_file)
    except _Refused as exc:
        print(f"tcp-pendant: error: {exc}", file=sys.stderr)
        return 2
    mode = "one robot shared by every browser" if args.shared else "one robot per browser"
    if workers is not None:
        mode += (f"; {args.workers} server processes on port {app.port} (pids "
                 f"{', '.join(str(p) for p in [os.getpid(), *workers.pids])})")
    tip_mm = ", ".join(f"{v:.0f}" for v in app.reference_tip_m * 1000.0)
    in_class = getattr(app, "classroom", None) is not None
    token_from = token_source(args.trainer_token, args.trainer_token_file, os.environ if in_class else {})
    print(f"TCP Pendant ready in {time.perf_counter() - t0:.1f} s: {ready_urls(url, app.network_urls, args.host)}"
          f"\n  robot {app.robot_label}, tool {app.tool.label}, reference tip ({tip_mm}) mm, {mode}\n"
          f"  tool library {app.library.path}\n{_class_lines(app, token_from, args.print_token)}  Ctrl-C to stop.", flush=True)
    try:
        app.serve_forever()
    finally:
        if workers is not None:
            workers.stop()
        _drop_balance_file(balance_file, worker)
    return 0


def _check_processes(args: argparse.Namespace) -> tuple[int, int, int] | None:
    """Check ``--port`` and ``--workers``; returns this process's place among the ``--workers``
    processes (None: the first, or the only one). Several processes stop cleanly on SIGTERM.

    Raises:
        _Refused: a port or a number of workers out of range, ``--workers`` with ``--shared``.
    """
    from tcp_pendant.serve.workers import MAX_WORKERS, WorkerError, worker_index

    if not 0 <= args.port <= 65535:
        raise _Refused(f"--port must be 0..65535, got {args.port}")
    if not 1 <= args.workers <= MAX_WORKERS:
        raise _Refused(f"--workers must be 1..{MAX_WORKERS}, got {args.workers}")
    if args.workers > 1 and args.shared:
        raise _Refused("--shared is one robot in one process; drop --workers or --shared")
    try:
        worker = worker_index()
    except WorkerError as exc:
        raise _Refused(str(exc)) from None
    if args.workers > 1 or worker is not None:
        import signal

        def _terminate(_signum: int, _frame: object) -> None:
            raise KeyboardInterrupt         # a clean stop: sessions end in the gradebook, names are freed

        signal.signal(signal.SIGTERM, _terminate)
    return worker


def _check_class(args: argparse.Namespace,
                 worker: tuple[int, int, int] | None) -> tuple[str | None, Path | str | None]:
    """Check the class's options (notes on stderr for a token or a password in the process list);
    returns the trainer token (None: the gradebook's, or a new one) and the class gradebook
    (None: no class; its folder made when it is the default file).

    Raises:
        _Refused: two tokens or a bad one, ``--shared`` with a class, a library quota out of
            place or range, a gradebook folder that cannot be made.
    """
    from tcp_pendant.classroom.gradebook_open import default_gradebook_path
    from tcp_pendant.classroom.library_rights import MAX_LIBRARY_QUOTA
    from tcp_pendant.classroom.trainer_token import TrainerTokenError, resolve_trainer_token

    classroom = bool(args.classroom or args.class_db or args.exercise or args.trainer_token
                     or args.trainer_token_file or args.exercise_instructions is not None
                     or args.exercise_methods is not None or args.exercise_min_touches is not None)
    try:                                    # the environment's token only matters for a class
        trainer_token = resolve_trainer_token(args.trainer_token, args.trainer_token_file,
                                              os.environ if classroom else {})
    except TrainerTokenError as exc:
        raise _Refused(str(exc)) from None
    if args.shared and classroom:
        raise _Refused("--shared is a lecture demo without names or gradebook; drop "
                       "--class / --class-db / --exercise / --exercise-instructions / --exercise-methods / "
                       "--exercise-min-touches / --trainer-token / --trainer-token-file, or drop --shared")
    if args.trainer_token is not None and worker is None:
        print("tcp-pendant: note: a --trainer-token on the command line shows in the process list; "
              "--trainer-token-file PATH or TCP_PENDANT_TRAINER_TOKEN keep it out", file=sys.stderr)
    if args.library_quota is not None and not classroom:
        raise _Refused("--library-quota is for a class (each trainee's own library slots); "
                       "add --class, or drop --library-quota")
    if args.library_quota is not None and not 1 <= args.library_quota <= MAX_LIBRARY_QUOTA:
        raise _Refused(f"--library-quota must be 1..{MAX_LIBRARY_QUOTA} slots, got {args.library_quota}")
    class_db = args.class_db
    if isinstance(class_db, str) and url_has_password(class_db):
        print("tcp-pendant: note: a password in the --class-db URL shows in the process list; "
              "PGPASSWORD or ~/.pgpass keep it out", file=sys.stderr)
    if classroom and class_db is None:
        class_db = default_gradebook_path()
        try:
            class_db.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise _Refused(f"cannot make the folder of the class gradebook {class_db.parent}: "
                           f"{exc}; give another file with --class-db PATH") from None
    return trainer_token, class_db


def _make_app(args: argparse.Namespace, trainer_token: str | None, class_db: Path | str | None,
              balance_file: Path | None, worker: tuple[int, int, int] | None) -> PendantApp:
    """The app the options describe (the robot loaded, not serving yet); its warnings printed
    by the first process.

    Raises:
        _Refused: the robot, a file, the gradebook or an option refused (the balance file is
            dropped).
    """
    from tcp_pendant.classroom.gradebook_store import GradebookError
    from tcp_pendant.classroom.library_rights import DEFAULT_LIBRARY_QUOTA
    from tcp_pendant.controller import ControllerError
    from tcp_pendant.serve.server import AppConfig, PendantApp, parse_xyz_mm

    try:
        tip = None if args.reference_tip is None else parse_xyz_mm(args.reference_tip)
        config = AppConfig(robot=args.robot, package_paths=tuple(args.package_path), flange_link=args.flange_link, tool=args.tool, host=args.host,
                           port=args.port, tool_library=args.tool_library, shared=args.shared,
                           reference_tip_mm=tip, allow_origins=tuple(args.allow_origin), class_db=class_db,
                           trainer_token=trainer_token, exercise=args.exercise,
                           exercise_seed=args.exercise_seed,
                           library_quota=(DEFAULT_LIBRARY_QUOTA if args.library_quota is None
                                          else args.library_quota),
                           exercise_instructions=args.exercise_instructions,
                           exercise_methods=None if args.exercise_methods is None else tuple(
                               m.strip() for m in args.exercise_methods.split(",") if m.strip()),
                           exercise_min_touches=args.exercise_min_touches, scenario=args.scenario.replace("-", "_"),
                           scenario_seed=args.scenario_seed, presenter=args.presenter,
                           hide_truth=args.hide_truth,
                           beam_width_mm=args.beam_width, beam_repeatability_mm=args.beam_repeatability,
                           beam_crossed=args.beam_crossed, seed=args.seed, language=args.language,
                           reuse_port=args.workers > 1 or worker is not None,
                           balance_file=balance_file)
        app = PendantApp(config)
    except (ControllerError, ValueError, OSError, GradebookError) as exc:
        _drop_balance_file(balance_file, worker)
        raise _Refused(str(exc)) from None
    if worker is None:                      # a worker's warnings are the first process's
        for line in app.warnings:
            print(f"WARNING: {line}", file=sys.stderr)
        warning = network_warning(args.host)
        if warning is not None:
            print(warning, file=sys.stderr)
    return app


def _start(app: PendantApp, args: argparse.Namespace, balance_file: Path | None,
           worker: tuple[int, int, int] | None) -> str:
    """Start serving ``app``; returns its URL.

    Raises:
        _Refused: the port is in use or cannot be listened on (the balance file is dropped).
        KeyboardInterrupt: Ctrl-C while starting (the app is stopped first).
    """
    from tcp_pendant.serve.server import PortInUseError

    try:
        return app.start()
    except PortInUseError as exc:
        _drop_balance_file(balance_file, worker)
        raise _Refused(str(exc)) from None
    except OSError as exc:
        _drop_balance_file(balance_file, worker)
        raise _Refused(f"cannot listen on {args.host}:{args.port}: {exc}") from None
    except KeyboardInterrupt:
        app.stop()
        _drop_balance_file(balance_file, worker)
        raise


def _start_workers(app: PendantApp, args: argparse.Namespace, argv: Sequence[str] | None,
                   balance_file: Path | None) -> Workers | None:
    """Start the other ``--workers`` processes on the app's port (None: one process).

    Raises:
        _Refused: a worker did not start (the app is stopped, the balance file dropped).
        KeyboardInterrupt: Ctrl-C while they start (likewise).
    """
    from tcp_pendant.serve.balance import BALANCE_ENV
    from tcp_pendant.serve.workers import WorkerError, Workers

    if args.workers <= 1:
        return None
    balance = app.balance
    workers = Workers(list(argv or ()), app.port, args.workers,
                      env={} if balance_file is None else {BALANCE_ENV: str(balance_file)},
                      on_stopped=None if balance is None else balance.turn_off)
    try:
        workers.start()
    except (WorkerError, OSError) as exc:
        app.stop()
        _drop_balance_file(balance_file, None)
        raise _Refused(str(exc)) from None
    except KeyboardInterrupt:
        app.stop()
        _drop_balance_file(balance_file, None)
        raise
    return workers


def _drop_balance_file(balance_file: Path | None, worker: tuple[int, int, int] | None) -> None:
    """The first process removes the balance record's folder when it stops."""
    if balance_file is not None and worker is None:
        shutil.rmtree(balance_file.parent, ignore_errors=True)


def _balance_file(workers: int, worker: tuple[int, int, int] | None) -> Path | None:
    """The record the ``--workers`` processes share to balance their connections
    (``tcp_pendant.serve.balance``): made by the first process in a folder of its own, named to the
    others in their environment; None for a single process."""
    from tcp_pendant.serve.balance import BALANCE_ENV, BalanceFile

    if worker is not None:
        value = os.environ.get(BALANCE_ENV)
        return Path(value) if value else None
    if workers <= 1:
        return None
    path = Path(tempfile.mkdtemp(prefix="tcp-pendant-workers-")) / "balance.json"
    BalanceFile.create(path, workers)
    return path


def set_apart_startup_objects() -> int:
    """Collect the start-up garbage, then move every object left (the robot model, meshes,
    viser's server: they live as long as the process) out of the cyclic collector's reach
    (``gc.freeze``), so that a full collection while a class jogs walks only the sessions'
    objects: its pause stalls every robot of the process at once (one full collection took
    0.1-0.3 s with 30 sessions). Returns how many objects are set apart."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()


def _serve_as_worker(app: PendantApp, parent_pid: int) -> int:
    """A worker of ``--workers N`` (``tcp_pendant.serve.workers``): say it listens, then serve until
    stopped or until the first process is gone."""
    print(f"worker ready {os.getpid()}", flush=True)
    devnull = os.open(os.devnull, os.O_WRONLY)      # nobody reads this pipe any more
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    app.serve_forever(alive=lambda: os.getppid() == parent_pid)
    return 0


def _class_lines(app: PendantApp, source: str = "", print_token: bool = False) -> str:
    """The classroom lines of the ready message (``serve.token_notice``: the token masked)."""
    return class_lines(app, source, print_token)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
