"""``tcp-pendant poses import FILE --robot``: joint-representation points become flange poses by
forward kinematics, checked against a hand-made URDF whose chain is composed by hand here."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcp_pendant.serve.cli import main
from tcpcal.cli import main as tcpcal_main

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)

DATA = Path(__file__).resolve().parents[1] / "data" / "controller_files"

# joint: (parent, child, origin xyz m, axis)
CHAIN = [("base_link", "l1", (0, 0, 0.4), "z"), ("l1", "l2", (0.1, 0, 0), "y"),
         ("l2", "l3", (0, 0, 0.5), "y"), ("l3", "l4", (0.4, 0, 0), "x"),
         ("l4", "l5", (0, 0, 0), "y"), ("l5", "flange", (0.1, 0, 0), "x")]


def write_urdf(path: Path) -> Path:
    links = "".join(f'<link name="{n}"/>' for n in ["base_link"] + [c[1] for c in CHAIN])
    axis = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}
    joints = "".join(
        f'<joint name="J{k}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
        f'<origin xyz="{" ".join(map(str, o))}" rpy="0 0 0"/><axis xyz="{axis[a]}"/>'
        f'<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        for k, (p, c, o, a) in enumerate(CHAIN, 1))
    path.write_text(f'<robot name="hand">{links}{joints}</robot>')
    return path


def hand_fk(q_deg: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """T_world_flange composed joint by joint: translate by the origin, rotate about the axis."""
    R, p = np.eye(3), np.zeros(3)
    for (_, _, origin, axis), q in zip(CHAIN, q_deg):
        p = p + R @ np.array(origin, dtype=float)
        R = R @ Rotation.from_euler(axis, q, degrees=True).as_matrix()
    return R, p * 1000.0


Q2 = [10.0, -20.0, 35.0, 5.0, -60.0, 15.0]
Q4 = [-30.0, 10.0, -5.0, 40.0, 25.0, -90.0]
LS = f"""/PROG  MIXED
/ATTR
DEFAULT_GROUP	= 1,*,*,*,*;
/MN
   1:J P[1] 10% FINE ;
   2:J P[2] 10% FINE ;
   3:J P[3] 10% FINE ;
   4:J P[4] 10% FINE ;
/POS
P[1]{{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    815.103  mm,	Y =   -161.836  mm,	Z =    560.115  mm,
	W =    180.000 deg,	P =       .000 deg,	R =      0.000 deg
}};
P[2]{{
   GP1:
	UF : 0, UT : 0,
	J1=  {Q2[0]:.3f} deg,	J2=  {Q2[1]:.3f} deg,	J3=  {Q2[2]:.3f} deg,
	J4=  {Q2[3]:.3f} deg,	J5=  {Q2[4]:.3f} deg,	J6=  {Q2[5]:.3f} deg
}};
P[3]{{
   GP1:
	UF : 0, UT : 0,		CONFIG : 'N U T, 0, 0, 0',
	X =    880.280  mm,	Y =   -133.007  mm,	Z =    575.374  mm,
	W =    170.000 deg,	P =     20.000 deg,	R =     30.000 deg
}};
P[4]{{
   GP1:
	UF : 0, UT : 0,
	J1=  {Q4[0]:.3f} deg,	J2=  {Q4[1]:.3f} deg,	J3=  {Q4[2]:.3f} deg,
	J4=  {Q4[3]:.3f} deg,	J5=  {Q4[4]:.3f} deg,	J6=  {Q4[5]:.3f} deg
}};
/END
"""


def rows(text: str) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(text)))


def test_joint_points_become_the_flange_poses_of_the_forward_kinematics(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = write_urdf(tmp_path / "hand.urdf")
    program = tmp_path / "mixed.ls"
    program.write_text(LS)
    assert main(["poses", "import", str(program), "--robot", str(urdf)]) == 0
    out, err = capsys.readouterr()
    assert "2 points in joint representation converted to flange poses of hand.urdf" in err
    got = rows(out)
    assert [r["name"] for r in got] == ["P[1]", "P[2]", "P[3]", "P[4]"]  # file order
    assert list(got[0]) == ["name", "x", "y", "z", "w", "p", "r"]
    for r, q in ((got[1], Q2), (got[3], Q4)):
        R, p = hand_fk(q)
        np.testing.assert_allclose([float(r[k]) for k in "xyz"], p, atol=1e-4)
        R_csv = Rotation.from_euler("xyz", [float(r[k]) for k in "wpr"], degrees=True)
        assert np.degrees((R_csv.inv() * Rotation.from_matrix(R)).magnitude()) < 1e-5
    assert float(got[0]["x"]) == 815.103 and float(got[2]["w"]) == 170.0


def test_without_joint_points_the_csv_is_tcpcals(tmp_path: Path,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    assert tcpcal_main(["poses", "import", str(DATA / "touches.mod")]) == 0
    expect = capsys.readouterr().out
    assert main(["poses", "import", str(DATA / "touches.mod"), "--robot", "kr6"]) == 0
    assert capsys.readouterr().out == expect


def test_abb_jointtarget_on_the_builtin_kr6(kr6, capsys: pytest.CaptureFixture[str]) -> None:
    """jHome of touches_tool_wobj.mod: the KR 6's flange at those axis values."""
    assert main(["poses", "import", str(DATA / "touches_tool_wobj.mod"), "--robot", "kr6"]) == 0
    out, err = capsys.readouterr()
    got = {r["name"]: r for r in rows(out)}
    assert list(got)[-1] == "jHome" and len(got) == 7  # file order: declared last
    T = kr6.T_world_flange(np.radians([0, -30, 15, 0, 75, 90]))
    np.testing.assert_allclose([float(got["jHome"][k]) for k in "xyz"], T[:3, 3] * 1000, atol=1e-4)
    q = [float(got["jHome"][k]) for k in ("qw", "qx", "qy", "qz")]
    R = Rotation.from_quat([q[1], q[2], q[3], q[0]]).as_matrix()
    assert np.degrees(Rotation.from_matrix(R.T @ T[:3, :3]).magnitude()) < 1e-6
    assert "reached by moves with tool HeatGun" in err  # tcpcal's warnings still shown


def test_a_point_with_another_axis_count_is_one_error_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = write_urdf(tmp_path / "hand.urdf")
    program = tmp_path / "seven.ls"
    program.write_text(LS.replace(f"J6=  {Q4[5]:.3f} deg", f"J6=  {Q4[5]:.3f} deg, J7 = 1 deg"))
    assert main(["poses", "import", str(program), "--robot", str(urdf)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "P[4] has 7 axis values but the robot has 6 joints (J1, J2, J3, J4, J5, J6)" in err


def test_an_unknown_robot_is_one_error_line(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["poses", "import", str(DATA / "touches.mod"), "--robot", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Unknown robot 'nope'" in err


REAL = DATA / "real"


def test_yaskawa_pulse_positions_become_flange_poses_with_pulses_per_degree(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """R1_PRESS.JBI (a GP25's job, README of the real files): PULSE counts / pulses per degree
    are the axis values; the flange poses are the built-in gp12's at those values."""
    from tcp_pendant.controller import RobotKinematics
    from tcp_pendant.serve.server import resolve_robot

    ppd = [1000.0, -1200.0, 900.0, 600.0, 700.0, 400.0]
    job = REAL / "yaskawa_R1_PRESS_excerpt.JBI"
    assert main(["poses", "import", str(job), "--robot", "gp12"]) == 2
    assert "--pulses-per-degree" in capsys.readouterr().err
    assert main(["poses", "import", str(job), "--robot", "gp12", "--package-path", "/nonexistent",
                 "--pulses-per-degree", ",".join(map(str, ppd))]) == 0
    out, err = capsys.readouterr()
    got = rows(out)
    assert [r["name"] for r in got] == ["C00000", "C00001", "P00007", "P00008", "P00030"]
    assert "5 points in joint representation converted" in err
    kin = RobotKinematics.from_urdf(resolve_robot("gp12"))
    counts = [-111044, -86410, -81415, -4390, 7023, 2426]  # P00007
    T = kin.T_world_flange(np.radians([c / f for c, f in zip(counts, ppd)]))
    np.testing.assert_allclose([float(got[2][k]) for k in "xyz"], T[:3, 3] * 1000, atol=1e-4)
    factors = tmp_path / "robot.ppd"
    factors.write_text("# S L U\n1000 -1200 900\n# R B T\n600\n700\n400\n")
    assert main(["poses", "import", str(job), "--robot", "gp12",
                 "--pulses-per-degree", str(factors)]) == 0
    assert capsys.readouterr().out == out  # the same factors from a file
    assert main(["poses", "import", str(job), "--robot", "gp12",
                 "--pulses-per-degree", "1000,1000"]) == 2
    assert "has 6 axes but --pulses-per-degree gives 2 numbers" in capsys.readouterr().err


def test_a_controller_parameter_file_as_pulses_per_degree_is_refused_with_what_to_write(
        capsys: pytest.CaptureFixture[str]) -> None:
    """The GP25's ALL.PRM (README of the real files): integer blocks under ``///`` headers that
    name no axis nor unit; the pulses per degree are not guessed from it."""
    job, prm = REAL / "yaskawa_R1_PRESS_excerpt.JBI", REAL / "yaskawa_ALL_excerpt.PRM"
    with pytest.raises(SystemExit) as exit_:
        main(["poses", "import", str(job), "--robot", "gp12", "--pulses-per-degree", str(prm)])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert (f"{prm}: a Yaskawa parameter file (/ALL YAS); tcp-pendant does not read pulses per "
            "degree from it. Write the robot's pulses per degree, one number per axis S L U R B "
            "T, in a plain text file (docs/pendant-cli.md) or give them as S,L,U,R,B,T") in err
    assert "20,100,1" not in err  # the file's numbers are not echoed


def test_an_unreadable_pulses_per_degree_file_is_named_not_echoed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    factors = tmp_path / "robot.ppd"
    factors.write_text("S 1000\nL 1200\n")
    with pytest.raises(SystemExit):
        main(["poses", "import", str(REAL / "yaskawa_R1_PRESS_excerpt.JBI"), "--robot", "gp12",
              "--pulses-per-degree", str(factors)])
    err = capsys.readouterr().err
    assert f"{factors}: give one number per axis, e.g. 1300.5,1300.5,1100,800,800,500" in err
    assert "S,1000" not in err


def test_pulses_per_degree_for_a_format_without_encoder_counts_is_one_error_line(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["poses", "import", str(REAL / "abb_Rob1_MainModule_excerpt.mod"), "--robot",
                 "kr6", "--pulses-per-degree", "1,1,1,1,1,1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].endswith(
        "--pulses-per-degree: ABB files hold no positions in encoder counts; leave it out")


def test_package_path_finds_the_packages_of_a_xacro_description(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """A cell xacro outside any package that includes the acme7 macro (tests/support/
    ros_layouts.py) by $(find acme_description): without ROS_PACKAGE_PATH only --package-path
    finds it, as the server's option does."""
    from support.ros_layouts import acme7_workspace
    from tcp_pendant.controller import RobotKinematics

    ws = acme7_workspace(tmp_path / "robot")
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    cell = tmp_path / "cell" / "cell.urdf.xacro"
    cell.parent.mkdir()
    cell.write_text(ws.xacro.read_text())
    q = [10.0, -20.0, 15.0, 30.0, -25.0, 40.0, 5.0]
    joints = ",\t".join(f"J{k}=  {v:.3f} deg" for k, v in enumerate(q, 1))
    program = tmp_path / "seven.ls"
    program.write_text(f"/PROG  SEVEN\n/MN\n   1:J P[1] 10% FINE ;\n/POS\nP[1]{{\n   GP1:\n"
                       f"\tUF : 0, UT : 0,\n\t{joints}\n}};\n/END\n")
    assert main(["poses", "import", str(program), "--robot", str(cell)]) == 2
    assert "acme_description" in capsys.readouterr().err
    assert main(["poses", "import", str(program), "--robot", str(cell),
                 "--package-path", str(ws.ros_package_path)]) == 0
    (row,) = rows(capsys.readouterr().out)
    kin = RobotKinematics.from_urdf(ws.xacro)
    T = kin.T_world_flange(np.radians(q))
    np.testing.assert_allclose([float(row[k]) for k in "xyz"], T[:3, 3] * 1000.0, atol=1e-4)
