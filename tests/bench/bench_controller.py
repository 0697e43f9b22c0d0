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
4. one ``auto_approach`` (IK from the current configuration, typical demo call).

Every figure is the median of repeated single calls timed with ``time.perf_counter_ns``.
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
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
