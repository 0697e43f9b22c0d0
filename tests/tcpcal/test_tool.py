"""Tool and Calibration data: validation, KUKA A, B, C convention, dict/JSON contract."""

from __future__ import annotations

import dataclasses
import json
import math
from datetime import datetime, timezone

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.tool import Calibration, Tool


def Rz(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def Ry(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def Rx(deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def test_rotation_is_kuka_rz_ry_rx_built_by_hand():
    tool = Tool("t", (1.0, 2.0, 3.0), (30.0, -20.0, 75.0))
    np.testing.assert_allclose(tool.rotation, Rz(30) @ Ry(-20) @ Rx(75), atol=1e-15)
    T = tool.T_flange_tool_mm
    np.testing.assert_allclose(T[:3, :3], tool.rotation)
    np.testing.assert_allclose(T[:3, 3], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(T[3], [0, 0, 0, 1])
    # B = -90: tool X along flange Z (a straight pointer along the flange axis)
    np.testing.assert_allclose(Tool("p", (0, 0, 200), (0, -90, 0)).rotation[:, 0], [0, 0, 1],
                               atol=1e-15)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 0.1))
def test_from_rotation_reproduces_any_rotation(q):
    R = Rotation.from_quat(np.array(q) / np.linalg.norm(q)).as_matrix()
    tool = Tool.from_rotation("t", [10.0, -20.0, 30.0], R, mass_kg=1.5)
    np.testing.assert_allclose(tool.rotation, R, atol=1e-9)
    assert all(-180.0 <= a <= 180.0 for a in tool.abc_deg)
    assert -90.0 <= tool.abc_deg[1] <= 90.0
    assert tool.mass_kg == 1.5


def test_from_rotation_gimbal_lock_without_warning(recwarn):
    R = Rz(40) @ Ry(90) @ Rx(10)
    tool = Tool.from_rotation("g", (0, 0, 0), R)
    np.testing.assert_allclose(tool.rotation, R, atol=1e-9)
    assert tool.abc_deg[1] == pytest.approx(90.0)
    assert not [w for w in recwarn if "Gimbal" in str(w.message)]


@pytest.mark.parametrize("offset_rad", [0.0, 1e-12, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_from_rotation_is_exact_next_to_gimbal_lock(offset_rad, sign):
    # scipy's as_euler snaps to the lock within ~1e-7 rad; the tool must not lose that
    rng = np.random.default_rng(17)
    for _ in range(50):
        A, C = rng.uniform(-180.0, 180.0, size=2)
        B = sign * (90.0 - math.degrees(offset_rad))
        R = Rz(A) @ Ry(B) @ Rx(C)
        tool = Tool.from_rotation("g", (0, 0, 0), R)
        np.testing.assert_allclose(tool.rotation, R, rtol=0, atol=1e-11)
    # the hypothesis counterexample that exposed it
    R = Rotation.from_quat(np.array([1.0, 0.0, 1.0, 1e-9]) / math.sqrt(2.0)).as_matrix()
    np.testing.assert_allclose(Tool.from_rotation("g", (0, 0, 0), R).rotation, R, atol=1e-12)


def test_from_rotation_rejects_non_rotation():
    with pytest.raises(InvalidInputError, match="orthonormal"):
        Tool.from_rotation("t", (0, 0, 0), np.eye(3) * 2)


def test_values_are_normalised_to_float_tuples():
    tool = Tool("t", np.array([1, 2, 3]), [0, 0, 90], mass_kg=2)
    assert tool.tcp_mm == (1.0, 2.0, 3.0) and isinstance(tool.tcp_mm[0], float)
    assert tool.abc_deg == (0.0, 0.0, 90.0)
    assert tool.mass_kg == 2.0 and isinstance(tool.mass_kg, float)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"name": ""}, "empty"),
        ({"name": "   "}, "empty"),
        ({"name": "x" * 25}, "at most 24"),
        ({"name": "a\tb"}, "control character"),
        ({"name": "new\nline"}, "control character"),
        ({"name": 'say "hi"'}, "double quote"),
        ({"name": " lead"}, "spaces"),
        ({"name": 5}, "string"),
        ({"tcp_mm": (1.0, 2.0)}, "3 numbers"),
        ({"tcp_mm": (1.0, float("nan"), 2.0)}, r"tcp_mm\[1\] must be a finite"),
        ({"tcp_mm": (1.0, "2", 2.0)}, "must be a number"),
        ({"abc_deg": (0.0, float("inf"), 0.0)}, "abc_deg"),
        ({"abc_deg": (True, 0.0, 0.0)}, "must be a number"),
        ({"mass_kg": 0.0}, "positive"),
        ({"mass_kg": -1.0}, "positive"),
        ({"mass_kg": float("nan")}, "finite"),
        ({"notes": 3}, "notes"),
        ({"calibration": {"method": "x"}}, "Calibration"),
    ],
)
def test_invalid_tools_raise_clear_errors(kwargs, match):
    base = {"name": "tool", "tcp_mm": (0.0, 0.0, 100.0)}
    base.update(kwargs)
    with pytest.raises(InvalidInputError, match=match):
        Tool(**base)


@pytest.mark.parametrize(
    ("name", "code"),
    [
        ("a\x7fb", "U+007F"),             # DEL (Cc)
        ("zero\u200bwidth", "U+200B"),     # ZERO WIDTH SPACE (Cf)
        ("evil\u202eloot", "U+202E"),      # RIGHT-TO-LEFT OVERRIDE (Cf): reverses the text shown
        ("nb\u00a0sp", "U+00A0"),          # NO-BREAK SPACE: looks like a space, is not one
        ("line\u2028sep", "U+2028"),       # LINE SEPARATOR (Zl)
        ("private\ue000", "U+E000"),       # private use (Co)
        ("esc\x1b[31m", "U+001B"),         # a terminal escape sequence
    ],
)
def test_name_with_an_invisible_or_control_character_is_refused_naming_it(name, code):
    with pytest.raises(InvalidInputError, match="control character") as err:
        Tool(name, (0, 0, 0))
    assert code in str(err.value)


@pytest.mark.parametrize("name", ["trail ", "\u3000ideographic", "tab\t"])
def test_name_with_surrounding_whitespace_is_refused(name):
    with pytest.raises(InvalidInputError, match="space|control character"):
        Tool(name, (0, 0, 0))


@pytest.mark.parametrize("name", ["Greifer-Übergabe", "トーチ 2", "Ø12 drill", "spot_gun.3"])
def test_printable_unicode_names_are_kept(name):
    assert Tool(name, (0, 0, 0)).name == name


def test_names_are_validated_where_they_are_made(tmp_path):
    """The one check in Tool covers a rename in the library and a name read from its file."""
    import dataclasses

    from tcpcal.library import ToolLibrary

    t = Tool("ok", (0, 0, 0))
    with pytest.raises(InvalidInputError, match="U\\+200B"):
        dataclasses.replace(t, name="o\u200bk")
    lib = ToolLibrary(tmp_path / "tools.json")
    lib.save(1, t)
    with pytest.raises(InvalidInputError, match="at most 24"):
        lib.rename(1, "n" * 25)
    assert lib.get(1).name == "ok"


def test_name_of_24_printable_characters_is_fine():
    name = "Gripper #2 (left) - 24ch"
    assert len(name) == 24
    assert Tool(name, (0, 0, 0)).name == name


def test_error_type_is_a_value_error():
    with pytest.raises(ValueError):
        Tool("", (0, 0, 0))
    assert issubclass(InvalidInputError, TcpcalError)


def test_frozen():
    tool = Tool("t", (0, 0, 0), calibration=Calibration.now("numeric", {"a": 1.0}))
    with pytest.raises(dataclasses.FrozenInstanceError):
        tool.name = "u"  # type: ignore[misc]
    with pytest.raises(TypeError):
        tool.calibration.figures["a"] = 2.0  # type: ignore[index]
    assert hash(tool) == hash(Tool("t", (0, 0, 0), calibration=tool.calibration))


def test_calibration_validation():
    Calibration("xyz4-lstsq", "2024-05-01T12:00:00Z", {"rms_error_mm": 0.2})
    Calibration("xyz4-lstsq", "2024-05-01T12:00:00+00:00")
    with pytest.raises(InvalidInputError, match="ISO 8601"):
        Calibration("xyz4-lstsq", "yesterday")
    with pytest.raises(InvalidInputError, match="time zone"):
        Calibration("xyz4-lstsq", "2024-05-01T12:00:00")
    with pytest.raises(InvalidInputError, match="non-empty"):
        Calibration("", "2024-05-01T12:00:00Z")
    with pytest.raises(InvalidInputError, match="finite"):
        Calibration("x", "2024-05-01T12:00:00Z", {"ci95_mm": float("inf")})


def test_calibration_now_is_utc_and_current():
    before = datetime.now(timezone.utc).replace(microsecond=0)
    cal = Calibration.now("reference", {"max_error_mm": 0.4})
    stamp = datetime.fromisoformat(cal.calibrated_at)
    assert stamp.utcoffset().total_seconds() == 0
    assert before <= stamp <= datetime.now(timezone.utc)


def test_dict_contract_keys_and_json_round_trip():
    cal = Calibration("three-point-1", "2024-05-01T12:00:00+00:00", {"defect_deg": 0.12})
    tool = Tool("torch", (12.5, 0.0, 180.25), (0.0, -90.0, 0.0), 2.5, "MIG 36", cal)
    d = tool.to_dict()
    # the documented, stable keys (a contract users script against)
    assert d == {
        "name": "torch",
        "tcp_mm": [12.5, 0.0, 180.25],
        "abc_deg": [0.0, -90.0, 0.0],
        "mass_kg": 2.5,
        "notes": "MIG 36",
        "calibration": {
            "method": "three-point-1",
            "calibrated_at": "2024-05-01T12:00:00+00:00",
            "figures": {"defect_deg": 0.12},
        },
    }
    back = Tool.from_dict(json.loads(json.dumps(d, allow_nan=False)))
    assert back == tool


def test_centre_of_gravity_key_only_when_known():
    """``cog_mm`` (FLANGE, mm) is written only for a tool that has one: the file of a tool
    without it keeps the keys it always had, and an old file without it still loads."""
    plain = Tool("p", (0, 0, 100), mass_kg=1.0)
    assert "cog_mm" not in plain.to_dict() and plain.cog_mm is None
    loaded = Tool("g", (0, 0, 100), mass_kg=2.0, cog_mm=(0, -4.5, 60))
    d = loaded.to_dict()
    assert list(d) == ["name", "tcp_mm", "abc_deg", "mass_kg", "cog_mm", "notes", "calibration"]
    assert d["cog_mm"] == [0.0, -4.5, 60.0]
    assert Tool.from_dict(json.loads(json.dumps(d))) == loaded
    for bad, needle in (((0, 1), "cog_mm must be 3 numbers"), ((0, float("nan"), 1), "finite"),
                        ("abc", "cog_mm must be 3 numbers")):
        with pytest.raises(InvalidInputError, match=needle):
            Tool("g", (0, 0, 100), cog_mm=bad)


def test_from_dict_defaults_and_errors():
    tool = Tool.from_dict({"name": "p", "tcp_mm": [0, 0, 100]})
    assert tool.abc_deg == (0.0, 0.0, 0.0) and tool.mass_kg is None and tool.calibration is None
    with pytest.raises(InvalidInputError, match=r"unknown keys \['mass'\]"):
        Tool.from_dict({"name": "p", "tcp_mm": [0, 0, 100], "mass": 2})
    with pytest.raises(InvalidInputError, match="lacks"):
        Tool.from_dict({"name": "p"})
    with pytest.raises(InvalidInputError, match="object"):
        Tool.from_dict(["p", [0, 0, 0]])
    with pytest.raises(InvalidInputError, match="calibration lacks"):
        Tool.from_dict({"name": "p", "tcp_mm": [0, 0, 1], "calibration": {"method": "x"}})
