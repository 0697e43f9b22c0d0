"""The controller-format registry (docs/architecture.md "Controller formats"): adding a format
touches one module. A toy format declared here, in the test alone, is offered by the CLI's
choices, converts, exports as text and as a file, imports poses and is a POSES.csv layout;
removed again, it is gone everywhere. Each built-in format's declaration is checked too."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tcpcal import controllers
from tcpcal.cli import build_parser, main
from tcpcal.controllers import (
    REGISTRY,
    ControllerFormat,
    CsvLayout,
    RecordedPose,
    ToolEntry,
    register,
    unregister,
)
from tcpcal.errors import InvalidInputError
from tcpcal.formats import FORMATS, export_tool, import_tool, text_format
from tcpcal.poses_csv import LAYOUTS, accepted_layouts_text, read_poses_csv
from tcpcal.tool import Tool

# ------------------------------------------------------------------ a toy format, test only
# "Toy" writes a frame as mm and a rotation vector in DEGREES: TOY x y z | u v w


def _rot(uvw_deg: Sequence[float]) -> np.ndarray:
    return Rotation.from_rotvec(np.radians(np.asarray(uvw_deg, dtype=float))).as_matrix()


def _uvw(rot: np.ndarray) -> tuple[float, ...]:
    return tuple(float(v) for v in np.degrees(Rotation.from_matrix(rot).as_rotvec()))


def _render_text(tool: Tool, slot: int = 1) -> str:
    u, v, w = _uvw(tool.rotation)
    x, y, z = tool.tcp_mm
    return f"TOY{slot} {x!r} {y!r} {z!r} | {u!r} {v!r} {w!r} #{tool.name}\n"


def _parse_text(text: str, name: str | None) -> Tool:
    m = re.search(r"TOY\d*\s+(\S+) (\S+) (\S+) \| (\S+) (\S+) (\S+)(?: #(.*))?", text)
    if not m:
        raise InvalidInputError("toy: no 'TOY x y z | u v w' found.")
    vals = [float(g) for g in m.groups()[:6]]
    return Tool.from_rotation(name or (m.group(7) or "toy").strip(), vals[:3], _rot(vals[3:]))


def _render_file(tool: Tool, number: int, name: str | None = None) -> str:
    text = _render_text(tool, number).replace("#" + tool.name, "#" + (name or tool.name))
    return "; toy controller file\n" + text


def _parse_file(text: str) -> list[ToolEntry]:
    t = _parse_text(text, None)
    return [ToolEntry(1, t.name, t.tcp_mm, t.rotation)]


def _parse_poses(text: str) -> list[RecordedPose]:
    out = []
    for k, m in enumerate(re.finditer(r"^HERE (\w+) (.*)$", text, re.M), 1):
        v = [float(s) for s in m.group(2).split()]
        out.append(RecordedPose(m.group(1), (v[0], v[1], v[2]), _rot(v[3:]), tuple(v[3:]),
                                line=k))
    return out


def _csv_rotations(values: np.ndarray, where: Callable[[int], str]) -> np.ndarray:
    return _rot(values)


TOY = ControllerFormat(
    name="toy", label="Toy (U, V, W)", rank=45,
    angle_convention="rotation vector in degrees", rotation_from_angles=_rot,
    angles_from_rotation=_uvw, numbers="x,y,z,u,v,w mm/deg", value_counts=(6,),
    values_to_text=lambda v: "TOY {} {} {} | {} {} {}".format(*v),
    render_text=_render_text, parse_text=_parse_text, tool_numbers=range(1, 5),
    controller="Toy controller", filename="toy{n}.txt", values="TOY x y z | u v w",
    render_file=_render_file, parse_file=_parse_file, parse_poses=_parse_poses,
    pose_extensions=(".toy",), detect=re.compile(r"^HERE ", re.M), detect_text="toy HERE",
    csv=CsvLayout("toy", ("tu", "tv", "tw"), "toy rotation vector in deg", _csv_rotations,
                  decimals=5, rank=45),
)


@pytest.fixture
def toy() -> Iterator[ControllerFormat]:
    register(TOY)
    try:
        yield TOY
    finally:
        unregister("toy")


def _choices(argv: list[str], dest: str) -> tuple[str, ...]:
    parser = build_parser()
    node = parser
    for word in argv:
        sub = next(a for a in node._actions if a.__class__.__name__ == "_SubParsersAction")
        node = sub.choices[word]  # type: ignore[attr-defined]
    action = next(a for a in node._actions if a.dest == dest)
    return tuple(action.choices)  # type: ignore[arg-type]


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_a_toy_format_declared_in_one_place_is_offered_everywhere(
        toy: ControllerFormat, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # choices of every command that names formats, in rank order (toy between ur and matrix)
    assert _choices(["convert"], "from_fmt") == ("kuka", "abb", "fanuc", "ur", "toy", "matrix")
    assert _choices(["convert"], "to_fmt") == ("kuka", "abb", "fanuc", "ur", "toy", "matrix")
    assert "toy" in _choices(["tools", "export"], "fmt")
    assert _choices(["poses", "import"], "fmt") == ("auto", "kuka", "abb", "fanuc", "ur", "toy",
                                                   "yaskawa")
    assert tuple(FORMATS) == ("kuka", "abb", "fanuc", "ur", "toy", "matrix")
    assert text_format("toy").label == "Toy (U, V, W)"  # the app's export list reads this

    # convert: bare values in the toy's own layout, and KUKA -> toy
    out = _run(capsys, "convert", "--from", "toy", "--to", "kuka", "10,20,30,0,0,90")
    assert out == "TOOL_DATA[1]={X 10.0,Y 20.0,Z 30.0,A 90.0,B 0.0,C 0.0}\nTOOL_NAME[1,]=\"tool\"\n"
    out = _run(capsys, "convert", "--from", "kuka", "--to", "toy", "--slot", "3",
               "1,2,3,0,0,-45")
    nums = [float(s) for s in re.findall(r"[-\d.e]+", out.split("|")[1].split("#")[0])]
    assert out.startswith("TOY3 1.0 2.0 3.0 |")
    np.testing.assert_allclose(nums, [-45.0, 0.0, 0.0], atol=1e-12)
    err_code = main(["convert", "--from", "toy", "--to", "kuka", "1,2,3"])
    assert err_code == 2
    assert "3 numbers given, 6 expected" in capsys.readouterr().err

    # the library API dispatches to it (round trip)
    tool = Tool("pin", (1.5, -2.0, 250.0), (10.0, 20.0, 30.0))
    back = import_tool(export_tool(tool, "toy", slot=2), "toy")
    np.testing.assert_allclose(back.T_flange_tool_mm, tool.T_flange_tool_mm, atol=1e-9)
    assert back.name == "pin"

    # tools export: the text and the whole file
    lib = str(tmp_path / "tools.json")
    _run(capsys, "tools", "--library", lib, "add", "2", "pin", "--xyz", "1.5,-2,250")
    assert _run(capsys, "tools", "--library", lib, "export", "2", "--format", "toy") \
        .startswith("TOY2 1.5 -2.0 250.0 | ")
    assert _run(capsys, "tools", "--library", lib, "export", "2", "--format", "toy", "--file",
                "--name", "other").startswith("; toy controller file\nTOY2 ")

    # poses import: by extension and by content, in the toy's own POSES.csv columns
    program = tmp_path / "touches.toy"
    program.write_text("HERE p1 100 0 500 0 90 0\nHERE p2 0 100 500 90 0 0\n")
    csv_text = _run(capsys, "poses", "import", str(program))
    assert csv_text == ("name,x,y,z,tu,tv,tw\np1,100.0000,0.0000,500.0000,0.00000,90.00000,"
                        "0.00000\np2,0.0000,100.0000,500.0000,90.00000,0.00000,0.00000\n")
    assert controllers.detect_pose_format(program.read_text()) == "toy"

    # POSES.csv: the layout table has it, in its rank, and read_poses_csv converts with it
    assert list(LAYOUTS) == ["kuka", "fanuc", "abb", "rotvec", "toy", "matrix"]
    assert LAYOUTS["toy"] == ("tu", "tv", "tw")
    assert "x,y,z,tu,tv,tw (toy rotation vector in deg)" in accepted_layouts_text()
    path = tmp_path / "poses.csv"
    path.write_text(csv_text)
    poses = read_poses_csv(path)
    assert poses.layout == "toy"
    np.testing.assert_allclose(poses.rotations[0], Rotation.from_euler("y", 90, degrees=True)
                               .as_matrix(), atol=1e-12)
    # and it solves like any layout (JSON names the layout)
    one = tmp_path / "one.csv"
    one.write_text("x,y,z,tu,tv,tw\n0,0,0,0,90,0\n")
    out = _run(capsys, "solve", "abc-world", str(one), "--json")
    assert '"layout": "toy"' in out


def test_a_removed_format_is_gone_everywhere(tmp_path: Path) -> None:
    register(TOY)
    unregister("toy")
    assert "toy" not in _choices(["convert"], "from_fmt")
    assert "toy" not in _choices(["tools", "export"], "fmt")
    assert "toy" not in FORMATS and "toy" not in LAYOUTS
    assert "tu" not in accepted_layouts_text()
    with pytest.raises(InvalidInputError, match="unknown tool format 'toy'"):
        export_tool(Tool("t", (0, 0, 0)), "toy")
    path = tmp_path / "p.csv"
    path.write_text("x,y,z,tu,tv,tw\n0,0,0,0,0,0\n")
    with pytest.raises(InvalidInputError, match="no orientation columns recognised"):
        read_poses_csv(path)


def test_registering_refuses_clashing_names_and_columns() -> None:
    with pytest.raises(InvalidInputError, match="registered already"):
        register(REGISTRY["kuka"])
    clash = ControllerFormat(
        name="clash", label="Clash", rank=99, angle_convention="-",
        rotation_from_angles=_rot, angles_from_rotation=_uvw,
        csv=CsvLayout("clash", ("a", "q"), "-", _csv_rotations))
    with pytest.raises(InvalidInputError, match="clashes with layout 'kuka'"):
        register(clash)
    with pytest.raises(InvalidInputError, match="taken"):
        register(ControllerFormat(
            name="clash", label="Clash", rank=99, angle_convention="-",
            rotation_from_angles=_rot, angles_from_rotation=_uvw,
            csv=CsvLayout("clash", ("role", "q9"), "-", _csv_rotations)))
    with pytest.raises(InvalidInputError, match="lower-case word"):
        register(ControllerFormat(name="auto", label="A", rank=1, angle_convention="-",
                                  rotation_from_angles=_rot, angles_from_rotation=_uvw))
    assert "clash" not in REGISTRY and "auto" not in REGISTRY


# ------------------------------------------------------------------ the built-in declarations
def test_the_registry_holds_each_format_once_in_menu_order() -> None:
    assert [f.name for f in controllers.formats()] == \
        ["kuka", "abb", "fanuc", "ur", "matrix", "yaskawa"]
    assert tuple(FORMATS) == ("kuka", "abb", "fanuc", "ur", "matrix")
    assert list(controllers.CONTROLLER_FORMATS) == ["kuka", "abb", "fanuc", "ur", "yaskawa"]
    assert tuple(controllers.POSE_FORMATS) == ("kuka", "abb", "fanuc", "ur", "yaskawa")
    assert [text_format(f).label for f in FORMATS] == ["KUKA", "ABB", "FANUC", "UR", "Matrix"]
    assert {n: lay.columns for n, lay in controllers.csv_layouts().items()} == {
        "kuka": ("a", "b", "c"), "fanuc": ("w", "p", "r"), "abb": ("qw", "qx", "qy", "qz"),
        "rotvec": ("rx", "ry", "rz"),
        "matrix": ("r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33")}


@pytest.mark.parametrize("name", ["kuka", "abb", "fanuc", "ur", "matrix", "yaskawa"])
def test_each_declared_angle_convention_is_its_own_inverse_and_matches_its_text(name: str) -> None:
    fmt = REGISTRY[name]
    rng = np.random.default_rng(3)
    for q in rng.normal(size=(20, 4)):
        rot = Rotation.from_quat(q / np.linalg.norm(q)).as_matrix()
        np.testing.assert_allclose(fmt.rotation_from_angles(fmt.angles_from_rotation(rot)), rot,
                                   atol=1e-12)
    # a hand-computed value of each convention: R = Rz(30 deg) about the tool's Z
    rz30 = Rotation.from_euler("z", 30, degrees=True).as_matrix()
    expected = {"kuka": (30.0, 0.0, 0.0), "fanuc": (0.0, 0.0, 30.0), "yaskawa": (0.0, 0.0, 30.0),
                "ur": (0.0, 0.0, np.radians(30.0)),
                "abb": (np.cos(np.radians(15)), 0.0, 0.0, np.sin(np.radians(15))),
                "matrix": tuple(rz30.reshape(9))}[name]
    np.testing.assert_allclose(fmt.angles_from_rotation(rz30), expected, atol=1e-12)


def test_slot_rules_come_from_each_format() -> None:
    assert REGISTRY["kuka"].slot_for(16) == 16
    assert REGISTRY["fanuc"].slot_for(10) == 10
    assert REGISTRY["fanuc"].slot_for(11) is None  # the app writes FANUC's default frame 1
    assert REGISTRY["abb"].slot_for(3) is None and REGISTRY["ur"].slot_for(3) is None
    assert REGISTRY["yaskawa"].slot_for(0) == 0 and REGISTRY["yaskawa"].slot_for(64) is None
    with pytest.raises(InvalidInputError, match=r"fanuc: tool number must be 1\.\.10, got 11"):
        export_tool(Tool("t", (0, 0, 0)), "fanuc", slot=11)


def test_no_module_outside_the_format_modules_names_a_vendor_format() -> None:
    """The dispatchers hold no vendor knowledge: no format name in a string literal."""
    src = Path(controllers.__file__).resolve().parents[1]
    for path in (src / "formats.py", src / "poses_csv.py", src / "cli.py",
                 src / "controllers" / "__init__.py"):
        code = re.sub(r'"""(.*?)"""', "", path.read_text(encoding="utf-8"), flags=re.S)
        code = "\n".join(ln.split("#")[0] for ln in code.splitlines())
        for name in ("kuka", "abb", "fanuc", "ur", "yaskawa", "matrix", "rotvec"):
            assert not re.search(rf"[\"']{name}[\"']", code), (path.name, name)
