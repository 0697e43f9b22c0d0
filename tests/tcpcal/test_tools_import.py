"""``tcpcal tools import FILE``: a controller file's tool table into the tool library
(docs/cli.md "tools import"), on files in the layouts the controllers save
(tests/data/controller_files, docs/formats.md cites the public sources)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from tcpcal.cli import main
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

DATA = Path(__file__).resolve().parents[1] / "data" / "controller_files"


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_a_yrc1000_tool_cnd_goes_into_the_slots_of_its_tool_numbers(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    code, out, err = run(["tools", "--library", str(lib), "import",
                          str(DATA / "TOOL_YRC1000.CND")], capsys)
    assert code == 0, err
    data = json.loads(lib.read_text())["tools"]
    assert sorted(data) == ["1", "3"]
    assert data["1"]["name"] == "TORCH" and data["3"]["name"] == "SPINDLE 2"
    assert data["1"]["tcp_mm"] == [12.345, 0.0, 350.0]
    assert data["1"]["mass_kg"] == 3.5 and data["1"]["cog_mm"] == [0.0, -4.5, 120.0]
    assert data["3"]["mass_kg"] == 48.2 and data["3"]["cog_mm"] == [-10.25, 15.0, -95.0]
    # Rx 90 about the flange X = KUKA C 90
    assert data["3"]["abc_deg"] == pytest.approx([0.0, 0.0, 90.0])
    assert "(5 unused entries skipped)" in out
    # tool 0 has no library slot: said, not silently dropped
    assert re.search(r"Yaskawa tool 0 'R1 STANDARD TOOL' not imported: the library has "
                     r"slots 1\.\.16", err)


def test_an_occupied_slot_is_refused_and_nothing_is_written(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    ToolLibrary(lib).save(3, Tool(name="mine", tcp_mm=(1, 2, 3)))
    before = lib.read_bytes()
    code, out, err = run(["tools", "--library", str(lib), "import",
                          str(DATA / "TOOL_YRC1000.CND")], capsys)
    assert code == 2
    assert "slot 3 ('mine') of the library is occupied; add --replace" in err
    assert lib.read_bytes() == before  # TORCH (slot 1, free) was not written either
    code, out, err = run(["tools", "--library", str(lib), "import", "--replace",
                          str(DATA / "TOOL_YRC1000.CND")], capsys)
    assert code == 0, err
    tools = ToolLibrary(lib).tools()
    assert tools[3].name == "SPINDLE 2" and tools[1].name == "TORCH"


def test_a_name_used_in_another_slot_is_refused(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    ToolLibrary(lib).save(9, Tool(name="TORCH", tcp_mm=(1, 2, 3)))
    code, _, err = run(["tools", "--library", str(lib), "import",
                        str(DATA / "TOOL_YRC1000.CND")], capsys)
    assert code == 2 and "'TORCH' is already in slot 9 of the library" in err
    assert sorted(ToolLibrary(lib).tools()) == [9]


def test_kuka_config_dat_names_and_an_unnamed_tool(tmp_path: Path,
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """TOOL_NAME[3,]=" " with all-zero data is an unused entry; a nameless tool with data
    becomes tool<n>."""
    text = (DATA / "config_excerpt.dat").read_text()
    text = text.replace("TOOL_DATA[3]={X 0.0,Y 0.0,Z 0.0", "TOOL_DATA[3]={X 5.0,Y 0.0,Z 90.0")
    src = tmp_path / "config.dat"
    src.write_text(text)
    lib = tmp_path / "tools.json"
    code, out, err = run(["tools", "--library", str(lib), "import", str(src)], capsys)
    assert code == 0, err
    tools = ToolLibrary(lib).tools()
    assert {s: t.name for s, t in tools.items()} == {1: "GUN", 2: "gripper", 3: "tool3"}
    assert tools[2].abc_deg == pytest.approx((90, -10, 5))
    assert tools[1].mass_kg is None  # LOAD_DATA M -1: KUKA's default, not a mass
    assert tools[3].tcp_mm == (5.0, 0.0, 90.0)


def test_abb_tools_without_numbers_fill_the_free_slots_in_file_order(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lib = tmp_path / "tools.json"
    ToolLibrary(lib).save(1, Tool(name="pointer", tcp_mm=(0, 0, 150)))
    code, out, err = run(["tools", "--library", str(lib), "import", "--format", "abb",
                          str(DATA / "calib_tools.mod")], capsys)
    assert code == 0, err
    tools = ToolLibrary(lib).tools()
    assert {s: t.name for s, t in tools.items()} == {1: "pointer", 2: "tGripper", 3: "tAngled"}
    assert tools[3].mass_kg == 25 and tools[3].cog_mm == (0.0, 0.0, 80.0)
    np.testing.assert_allclose(tools[2].tcp_mm, (0, 1, 330))


def test_a_name_the_library_refuses_is_a_clear_error(tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    src = tmp_path / "long.mod"
    src.write_text("MODULE M\n  PERS tooldata tAVeryLongToolNameOfThirtyOne1:=[TRUE,[[0,0,100],"
                   "[1,0,0,0]],[1,[0,0,10],[1,0,0,0],0,0,0]];\nENDMODULE\n")
    lib = tmp_path / "tools.json"
    code, _, err = run(["tools", "--library", str(lib), "import", str(src)], capsys)
    assert code == 2 and err.count("\n") == 1
    assert "ABB entry 1 'tAVeryLongToolNameOfThirtyOne1' cannot be stored" in err
    assert "at most 24" in err and not lib.exists()


@pytest.mark.parametrize(("name", "text", "fmt"), [
    ("TOOL.CND", "//TOOL 1\n///NAME A\n1,2,3,0,0,0\n0,0,0\n0\n0,0,0\n0.000,0,1\n", "yaskawa"),
    ("x.txt", "//TOOL 1\n///NAME A\n1,2,3,0,0,0\n0,0,0\n0\n0,0,0\n0.000,0,1\n", "yaskawa"),
    ("x.txt", 'TOOL_DATA[4]={X 1,Y 2,Z 3,A 0,B 0,C 0}\nTOOL_NAME[4,]="A"\n', "kuka"),
    ("x.txt", "set_tcp(p[0.001, 0.002, 0.003, 0, 0, 0])\n", "ur"),
])
def test_auto_detection(tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str,
                        text: str, fmt: str) -> None:
    src = tmp_path / name
    src.write_text(text)
    code, out, err = run(["tools", "--library", str(tmp_path / "l.json"), "import", str(src)],
                         capsys)
    assert code == 0, err
    assert out.startswith(f"Imported 1 {fmt} tool ")
    (tool,) = ToolLibrary(tmp_path / "l.json").tools().values()
    np.testing.assert_allclose(tool.tcp_mm, (1, 2, 3))
