"""Benchmark of the virtual controller (tcp_pendant.controller).

    python tests/bench/bench_controller.py [--quick]

Prints the median time (us) of, for each built-in robot (KR 6 R900, GP12):

1. one flange FK, ``RobotKinematics.T_world_flange`` (pinocchio; target < 10 us), against a
   baseline measured in the same run: the same FK with yourdfpy (``update_cfg`` +
   ``get_transform``), and pinocchio's ``link_poses`` (every link, for the scene);
2. one flange Jacobian, ``jacobian_flange``;
3. one Cartesian jog step, ``VirtualController.jog_cartesian`` of 1 mm in TOOL X with the torch
   as active tool from a working configuration (target < 200 us), a 1 deg rotation jog, and a
   10 mm step (5 sub-steps, as a continuous jog at 250 mm/s and 25 Hz sends);
4. one ``auto_approach`` (IK from the current configuration, typical demo call);
5. the server CPU of one pendant jog increment as the app runs it (``Jogger.key`` -> the
   controller's ``jog_cartesian`` -> ``jog.follow_path``), on the app's KR 6 with the pointer
   (TCP = flange, the reference tip and ready pose of ``tcp_pendant.serve.server``): 0.1 mm in WORLD
   (the class's "X +"), BASE (rotated) and TOOL, 1 mm, 1 deg and 0.1 deg rotations, and the
   torch's tool data active; against a baseline measured in the same run, ABAB: the jog as it
   was before the per-step speed work (``jog_yardstick.py``: the same math without the kept
   kinematics, the LU and midpoint Newton steps, the sigma bound and the contact pre-test). Per-increment
   thread CPU (``time.thread_time_ns`` over a block of presses, 25 one way then 25 back),
   median over the rounds, and the median of the per-round ratios.

Figures 1-4 are the median of repeated single calls timed with ``time.perf_counter_ns``.
``--quick`` runs few repetitions (used by tests/controller/test_bench_controller_runs.py).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np
import yourdfpy

from tcpcal.tool import Tool
from tcp_pendant.controller import RobotKinematics, VirtualController, builtin_robots, builtin_tools
from tcp_pendant.pendant.jogging import Jogger

if __name__ == "__main__":                  # run as a script: tests/ on sys.path (support.*, bench.*)
    import _tests_on_path  # noqa: F401
from bench.jog_yardstick import LegacyController, LegacyJogger

WORK_Q_DEG = {"kr6": (10.0, -80.0, 100.0, 20.0, 40.0, 30.0), "gp12": (10.0, 10.0, 10.0, 20.0, -50.0, 30.0)}
TIP_M = {"kr6": (0.55, 0.05, 0.25), "gp12": (0.95, 0.05, 0.35)}


def median_us(fn: Callable[[], object], repeats: int, setup: Callable[[], object] | None = None) -> float:
    """Median wall time of one call of ``fn`` in microseconds (``setup`` runs untimed before each)."""
    times = []
    for _ in range(repeats):
        if setup is not None:
            setup()
        t0 = time.perf_counter_ns()
        fn()
        times.append(time.perf_counter_ns() - t0)
    return statistics.median(times) / 1000.0


def bench_robot(key: str, repeats: int) -> dict[str, float]:
    kin = RobotKinematics.from_urdf(builtin_robots()[key])
    q = np.radians(WORK_Q_DEG[key])
    urdf = yourdfpy.URDF.load(str(kin.urdf_path), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)

    def yourdfpy_fk() -> np.ndarray:
        urdf.update_cfg(q)
        return urdf.get_transform(frame_to=kin.flange_link, frame_from=urdf.base_link)

    torch = builtin_tools()["torch"]
    T = torch.T_flange_tool_true
    ctrl = VirtualController(kin, tool=torch, reference_tip_world_m=TIP_M[key],
                             active_tool=Tool.from_rotation("torch", tuple(T[:3, 3] * 1000.0), T[:3, :3]))
    reset = lambda: ctrl.set_q(q)  # noqa: E731
    sign = [1.0]

    def jog_back_and_forth(axis: str, amount: float) -> Callable[[], object]:
        def step() -> object:
            sign[0] = -sign[0]  # alternate so the robot stays near the working configuration
            res = ctrl.jog_cartesian("TOOL", axis, sign[0] * amount)
            assert res.ok, res.message
            return res
        return step

    reset()
    out = {
        "fk_pinocchio": median_us(lambda: kin.T_world_flange(q), repeats * 10),
        "fk_yourdfpy": median_us(yourdfpy_fk, max(repeats // 2, 5)),
        "link_poses": median_us(lambda: kin.link_poses(q), repeats * 10),
        "jacobian": median_us(lambda: kin.jacobian_flange(q), repeats * 10),
        "jog_1mm": median_us(jog_back_and_forth("X", 1.0), repeats * 2),
        "jog_1deg": median_us(jog_back_and_forth("A", 1.0), repeats * 2),
        "jog_10mm": median_us(jog_back_and_forth("Y", 10.0), repeats),
    }
    rng = np.random.default_rng(0)
    directions = [(rng.uniform(0, 40), rng.uniform(0, 360), rng.uniform(-60, 60)) for _ in range(repeats)]
    it = iter(directions * 2)

    def approach() -> object:
        tilt, az, spin = next(it)
        return ctrl.auto_approach(tilt_deg=tilt, azimuth_deg=az, spin_deg=spin)

    out["auto_approach"] = median_us(approach, max(repeats // 4, 3), setup=reset)
    return out


INCREMENT_CASES = (  # (label, frame, axis, increment, torch tool data active)
    ("0.1 mm WORLD X (the class)", "WORLD", "X", "0.1", False),
    ("0.1 mm BASE Y", "BASE", "Y", "0.1", False),
    ("0.1 mm TOOL Z", "TOOL", "Z", "0.1", False),
    ("1 mm WORLD X", "WORLD", "X", "1", False),
    ("1 deg WORLD A", "WORLD", "A", "1", False),
    ("0.1 deg TOOL C", "TOOL", "C", "0.1", False),
    ("0.1 mm WORLD X, torch data", "WORLD", "X", "0.1", True),
    ("1 deg TOOL A, torch data", "TOOL", "A", "1", True),
)


def _app_jogger(kin: RobotKinematics, legacy: bool, frame: str, increment: str, torch_data: bool) -> Jogger:
    """A pendant's jogger on a controller built as ``PendantApp.new_controller`` builds it."""
    from tcp_pendant.serve.server import default_reference_tip_mm, ready_configuration  # viser: only here

    pointer = builtin_tools()["pointer"]
    tip_m = np.asarray(default_reference_tip_mm(kin, np.asarray(pointer.T_flange_tool_true)), dtype=float) / 1000.0
    ready = ready_configuration(kin, tip_m)
    cls = LegacyController if legacy else VirtualController
    c = cls(kin.own_copy(), tool=pointer, reference_tip_world_m=tip_m)
    c.set_q(ready)
    c.set_rest_configuration(ready)
    T_base = np.eye(4)
    T_base[:3, :3] = np.array([[0.0, -1.0, 0.0], [0.6, 0.0, -0.8], [0.8, 0.0, 0.6]])  # rotated work object
    T_base[:3, 3] = (0.4, -0.1, 0.2)
    c.set_T_world_base(T_base)
    if torch_data:
        T = builtin_tools()["torch"].T_flange_tool_true
        c.set_active_tool(Tool.from_rotation("torch", tuple(T[:3, 3] * 1000.0), T[:3, :3]))
    j = (LegacyJogger if legacy else Jogger)(c)
    j.settings = j.settings.with_(frame=frame, increment=increment)
    return j


def bench_increments(rounds: int, block: int = 50) -> list[tuple[str, float, float, float]]:
    """Per-increment thread CPU (us) of the new jog and of the yardstick: rows (label, new
    median, baseline median, median of the per-round ratios baseline / new)."""
    kin = RobotKinematics.from_urdf(builtin_robots()["kr6"])
    rows = []
    for label, frame, axis, increment, torch_data in INCREMENT_CASES:
        joggers = {legacy: _app_jogger(kin, legacy, frame, increment, torch_data) for legacy in (False, True)}
        per_inc: dict[bool, list[float]] = {False: [], True: []}

        def run(j: Jogger, n: int) -> None:
            for k in range(n):
                res = j.key(axis, 1 if (k // (block // 2)) % 2 == 0 else -1)
                assert res is not None and res.ok, (label, res)

        for j in joggers.values():
            run(j, block)                                  # warm up
        for r in range(rounds):
            for legacy in ((False, True) if r % 2 == 0 else (True, False)):
                t0 = time.thread_time_ns()
                run(joggers[legacy], block)
                per_inc[legacy].append((time.thread_time_ns() - t0) / block / 1000.0)
        ratios = [b / a for a, b in zip(per_inc[False], per_inc[True])]
        rows.append((label, statistics.median(per_inc[False]), statistics.median(per_inc[True]),
                     statistics.median(ratios)))
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="few repetitions (smoke test)")
    args = parser.parse_args(argv)
    repeats = 20 if args.quick else 400
    print("Virtual controller timings (median us per call)")
    print(f"{'robot':6s} {'figure':44s} {'median us':>10s}  target")
    for key in ("kr6", "gp12"):
        r = bench_robot(key, repeats)
        rows = [
            ("flange FK, pinocchio (T_world_flange)", r["fk_pinocchio"], "< 10"),
            ("flange FK, yourdfpy baseline", r["fk_yourdfpy"], ""),
            ("all link poses, pinocchio (link_poses)", r["link_poses"], ""),
            ("flange Jacobian (jacobian_flange)", r["jacobian"], ""),
            ("Cartesian jog step 1 mm TOOL X", r["jog_1mm"], "< 200"),
            ("Cartesian jog step 1 deg TOOL A", r["jog_1deg"], ""),
            ("Cartesian jog step 10 mm TOOL Y (5 sub-steps)", r["jog_10mm"], ""),
            ("auto_approach (IK)", r["auto_approach"], ""),
        ]
        for name, value, target in rows:
            print(f"{key:6s} {name:44s} {value:10.1f}  {target}")
        speedup = r["fk_yourdfpy"] / r["fk_pinocchio"]
        print(f"{key:6s} {'speed-up of pinocchio FK over yourdfpy':44s} {speedup:9.0f}x")
    rounds = 4 if args.quick else 30
    print()
    print("One pendant jog increment, KR 6 with the pointer as the app builds it (Jogger.key -> controller):")
    print(f"server thread CPU per increment, median of {rounds} rounds of 50 presses, ABAB against the "
          "jog before the per-step work")
    print(f"{'increment':34s} {'new us':>8s} {'baseline us':>12s} {'speed-up':>9s}")
    for label, new, base, ratio in bench_increments(rounds):
        print(f"{label:34s} {new:8.1f} {base:12.1f} {ratio:8.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
