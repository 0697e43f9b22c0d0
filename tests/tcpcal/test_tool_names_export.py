"""What each controller format does with a tool name (docs/cli.md, "Tool names"): every valid
tcpcal name gives valid controller text -- ABB a RAPID identifier, FANUC a 16-character
comment, KUKA the name itself in TOOL_NAME, UR no name at all."""

from __future__ import annotations

import re

import pytest

from tcpcal.formats import FANUC_COMMENT_LENGTH, export_tool, import_tool
from tcpcal.tool import MAX_NAME_LENGTH, Tool

RAPID_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")
NAMES = ["pointer", "2nd gripper-L", "Greifer-Übergabe", "トーチ", "IF", "true", "Module",
         "x" * MAX_NAME_LENGTH, "a.b/c\\d'e", "_under", "tool #3 (left)"]


def _abb_ident(text: str) -> str:
    m = re.match(r"PERS tooldata (\S+?):=\[", text)
    assert m, text
    return m.group(1)


@pytest.mark.parametrize("name", NAMES)
def test_abb_export_always_declares_a_valid_rapid_identifier(name):
    text = export_tool(Tool(name, (1, 2, 3)), "abb")
    ident = _abb_ident(text)
    assert RAPID_IDENTIFIER.fullmatch(ident), ident
    assert import_tool(text, "abb").tcp_mm == (1.0, 2.0, 3.0)


@pytest.mark.parametrize(("name", "ident"), [
    ("IF", "tIF"), ("true", "ttrue"), ("Module", "tModule"), ("ENDPROC", "tENDPROC"),
    ("pointer", "pointer"), ("2nd gripper-L", "t2nd_gripper_L"), ("Greifer-Übergabe",
                                                                 "Greifer__bergabe"),
    ("トーチ", "t___"), ("ifs", "ifs"),
])
def test_abb_identifier_rule(name, ident):
    assert _abb_ident(export_tool(Tool(name, (0, 0, 0)), "abb")) == ident


@pytest.mark.parametrize(("name", "comment"), [
    ("spot", "spot"),
    ("Gripper #2 (left) - 24ch", "Gripper #2 (left"),
    ("welding torch 22 deg", "welding torch 22"),
    ("abcdefghijklmno pq", "abcdefghijklmno"),  # the cut falls after a space: dropped
])
def test_fanuc_comment_holds_16_characters(name, comment):
    text = export_tool(Tool(name, (0, 0, 0)), "fanuc", slot=1)
    assert text.splitlines()[1] == f"Comment: {comment}"
    assert len(comment) <= FANUC_COMMENT_LENGTH == 16
    assert import_tool(text, "fanuc").name == comment


@pytest.mark.parametrize("name", NAMES)
def test_kuka_export_writes_the_name_as_a_krl_string(name):
    text = export_tool(Tool(name, (0, 0, 0)), "kuka", slot=4)
    assert text.splitlines()[1] == f'TOOL_NAME[4,]="{name}"'
    assert import_tool(text, "kuka").name == name


def test_ur_export_carries_no_name():
    assert "pointer" not in export_tool(Tool("pointer", (0, 0, 100)), "ur")
