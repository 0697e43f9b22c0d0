""""The math", its board and the presenter in the session's language (issue 47).

With the pseudo-locale (``qps``: every catalog message wrapped as ``⟦...⟧``) every word the
math panel, the math board and the presenter show comes from the catalogs, in every state of
every method of ``math_view.MATH_VIEWS``; the equations' symbols are exempt
(``support.math_text``). A live switch of the language re-renders them, keeps the chosen pair
and gives back the English text byte for byte.
"""

from __future__ import annotations

from collections.abc import Iterator
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from support.calib_helpers import library_tool_with_true_tcp
from support.calib_page import Page
from support.guiclick import choose
from support.math_text import untranslated_outside_math
from support.pseudo_text import WORD, gui_texts
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.math_board import board_html
from tcp_pendant.calibrate.math_view import MATH_VIEWS, math_markdown, math_sheet
from tcp_pendant.translation import PSEUDO_LANGUAGE, translator

pytestmark = pytest.mark.app_page(cls=Page, seed=5)

NAMES = {"WORLD", "FLANGE", "TOOL", "mm", "deg", "X", "Y", "Z", "A", "B", "C", "TCP"}
"""Frame names, units and axis names: the same in every language."""


def _wizard_words(s) -> set[str]:
    """The words the wizard gives: its method's title (its class's msgid, wrapped by the wizards'
    part of issue 47) and its steps' titles (they come in the wizard's language), and the active
    tool's name (user text: the presenter's "Tool data")."""
    wiz = s.workflow.wizard
    texts = [str(getattr(type(wiz), "title", ""))] + [str(st.title) for st in getattr(wiz, "steps", ())]
    tool = s.controller.active_tool
    texts += [tool.name] if tool is not None else []
    return {w for t in texts for w in WORD.findall(t)}


def _texts(s) -> Iterator[tuple[str, str]]:
    """Every text of the math panel, the presenter and its board (presenter mode is on)."""
    math = s.views["calibrate"].math
    for name in ("folder", "pair", "md"):
        for text in gui_texts(getattr(math, name)):
            yield f"math.{name}", text
    presenter = s.views["presenter"]
    for name in ("toggle", "folder", "readout_md", "tool_md", "steps_md"):
        for text in gui_texts(getattr(presenter, name)):
            yield f"presenter.{name}", text
    chart = presenter.chart
    yield "chart.title", str(chart.title)
    for series in chart.series:
        yield "chart.series", str(series.get("label", ""))
    for axis in chart.axes or ():
        yield "chart.axis", str(axis.get("label", ""))
    board = presenter.board
    for text in gui_texts(board.toggle):
        yield "board.toggle", text
    yield "board.html", board.html.content


def math_board_content(s) -> str:
    return str(s.views["presenter"].board.html.content)


def check_all_from_catalogs(s) -> int:
    """Asserts every text is from the catalogs; returns how many texts it checked."""
    names = NAMES | _wizard_words(s)
    n = 0
    with s.lock:
        for where, text in _texts(s):
            assert untranslated_outside_math(text, names) == [], (where, text)
            n += 1
    return n


def touch(s, n: int = 1, **request: float) -> None:
    for _ in range(n):
        with s.lock:
            assert s.wizard_commands.auto_touch(AutoTouchRequest(**request)).ok


def _in_pseudo_locale_with_the_board(p) -> None:
    s = p.session
    s.set_language(PSEUDO_LANGUAGE)
    presenter = s.views["presenter"]
    choose(presenter.toggle, True, s.client)
    choose(presenter.board.toggle, True, s.client)
    assert presenter.board.html.visible


def test_every_math_view_shows_only_catalog_words_in_the_pseudo_locale(page) -> None:
    """Each method of ``MATH_VIEWS`` from its start to its result, its blocks as they come."""
    p = page(tool="torch")
    s = p.session
    _in_pseudo_locale_with_the_board(p)
    seen: set[str] = set()
    keys: set[str] = set()
    torch_tool = library_tool_with_true_tcp("torch", "Torch")
    s.library.save(1, torch_tool)

    def step(n: int = 1, **request: float) -> None:
        for _ in range(n):
            touch(s, **request)
            assert check_all_from_catalogs(s) > 10
            sheet = s.views["calibrate"].math.sheet
            keys.update(b.key for b in sheet.blocks)

    for kind, options, touches in (("xyz4", {"n_points": 5}, 5), ("three-point", {"slot": 1}, 3),
                                   ("abc-world", {"slot": 1}, 1), ("abc-world", {"slot": 1, "variant": "5d"}, 1),
                                   ("tcp-zx", {"n_points": 4}, 6)):
        with s.lock:
            s.wizard_commands.start(kind, **options)
        seen.add(type(s.workflow.wizard).math_view)
        check_all_from_catalogs(s)                               # no pose yet
        step(touches, sigma_mm=0.3)
    with s.lock:                                                 # three-point, variant 2
        s.wizard_commands.start("three-point", slot=1, variant=2)
    step(3, sigma_mm=0.3)
    with s.lock:                                                 # the result's pair dropdown
        s.wizard_commands.start("xyz4", n_points=4)
    step(4, sigma_mm=0.3)
    math = s.views["calibrate"].math
    assert math.pair.visible and len(math.pair.options) == 7     # last two + 6 pairs
    choose(math.pair, math.pair.options[2], s.client)
    check_all_from_catalogs(s)

    s.library.save(2, library_tool_with_true_tcp("pointer", "Pointer"))
    with s.lock:
        s.wizard_commands.start("reference", slot=2, reference_tool_key="pointer", new_tool_key="torch")
    seen.add("reference")
    step()
    with s.lock:
        s.wizard_commands.mount_required_tool()
    step()

    for kind, options in (("beam", {}), ("tcp-check", {"slot": 1})):
        with s.lock:
            s.wizard_commands.start(kind, **options)
        seen.add(type(s.workflow.wizard).math_view)
        check_all_from_catalogs(s)                               # before the scan / the spins
        with s.lock:
            if kind == "tcp-check":                              # a pose the six spins can be made from
                assert any(s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=tilt, azimuth_deg=azimuth)).ok
                           for tilt in (25.0, 15.0, 0.0) for azimuth in (30.0, 120.0, 210.0, 300.0))
            s.wizard_commands.next_step()
        keys.update(b.key for b in s.views["calibrate"].math.sheet.blocks)
        check_all_from_catalogs(s)

    assert seen == set(MATH_VIEWS)
    assert {"touch-1", "A", "pair", "stack", "lstsq", "sphere", "eq7", "eq8-17", "eq18-24", "eq25-29", "eq30",
            "pa", "axis-z", "axis-x", "frame", "reference-point", "new-tcp", "event-1", "spin"} <= keys


def _turning_about_one_axis(n: int) -> SimpleNamespace:
    """A 4-point wizard's record (what ``math_sheet`` reads) of ``n`` exact touches whose tool
    turns about WORLD Z only: the TCP along that axis is unobservable, the flange origins lie on
    one circle (a plane), so the stack stays rank 2, the solver refuses and the sphere cannot
    be fitted."""
    t_mm, r_mm = np.array([10.0, 20.0, 150.0]), np.array([600.0, 50.0, 300.0])
    poses = {}
    for i in range(n):
        R = Rotation.from_euler("zx", [40.0 * i, 180.0], degrees=True).as_matrix()
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, (r_mm - R @ t_mm) / 1000.0          # metres, as recorded
        poses[i] = SimpleNamespace(T_world_flange_m=T)

    class Wizard(SimpleNamespace):
        math_view = "xyz4"
        title = "XYZ 4-point"

    return Wizard(recorded_poses=poses, steps=[SimpleNamespace(role="touch") for _ in range(n)], excluded=())


def test_the_degenerate_touches_words_are_from_the_catalogs_too() -> None:
    """The words a good run never shows: a stack of rank 2 from more than two touches, the
    solver's refusal (in our words, not tcpcal's English), no sphere."""
    qps, names = translator(PSEUDO_LANGUAGE), NAMES | {"XYZ", "point"}
    sheet = math_sheet(_turning_about_one_axis(4), tr=qps)
    assert sheet is not None and sheet.has("lstsq") and sheet.has("sphere")
    assert sheet.block("lstsq").lines == (qps.gettext("no solution yet"),)
    assert sheet.block("sphere").lines == (qps.gettext("no sphere yet"),)
    assert "⟦Åļļ ţöûçĥéš ŕöţåţé" in sheet.block("stack").note and "⟦Åļļ ţöûçĥéš ŕöţåţé" in sheet.block("lstsq").note
    md = math_markdown(sheet, tr=qps)
    assert untranslated_outside_math(md, names) == []
    assert untranslated_outside_math(board_html(sheet, tr=qps), names) == []
    assert untranslated_outside_math(math_markdown(None, tr=qps), set()) == []
    assert untranslated_outside_math(board_html(None, tr=qps), set()) == []
    english = math_sheet(_turning_about_one_axis(4))
    assert english is not None and english.block("lstsq").note.startswith("All touches rotate about nearly")


def test_a_language_switch_re_renders_the_math_keeping_the_pair_and_english_comes_back_byte_for_byte(page) -> None:
    p = page()
    s = p.session
    presenter = s.views["presenter"]
    choose(presenter.toggle, True, s.client)
    choose(presenter.board.toggle, True, s.client)
    with s.lock:
        s.wizard_commands.start("xyz4")
    touch(s, 3, sigma_mm=0.3)
    math = s.views["calibrate"].math
    choose(math.pair, "1 and 3", s.client)
    pair = math.sheet.block("pair").values["R_a-R_b"].value
    english = list(_texts(s))
    assert ("math.folder", "The math") in english and "1 and 3" in math.pair.options
    assert 'data-toggle="Math board" data-back="Back to the pendant"' in math_board_content(s)

    s.set_language(PSEUDO_LANGUAGE)
    with s.lock:
        pseudo = list(_texts(s))
        assert math.pair.value == "⟦{a} åñð {b}⟧".replace("{a}", "1").replace("{b}", "3")   # the same pair
        np.testing.assert_array_equal(math.sheet.block("pair").values["R_a-R_b"].value, pair)
    assert check_all_from_catalogs(s) > 10
    assert [w for w, _ in pseudo] == [w for w, _ in english]
    changed = {w for (w, before), (_, after) in zip(english, pseudo) if before != after}
    assert {"math.folder", "math.pair", "math.md", "presenter.toggle", "presenter.folder", "presenter.readout_md",
            "presenter.tool_md", "chart.title", "chart.series", "chart.axis", "board.toggle", "board.html"} <= changed
    assert 'data-toggle="⟦Ṁåţĥ ƀöåŕð⟧"' in math_board_content(s)     # the page script finds the checkbox by it

    s.set_language("en")
    with s.lock:
        assert list(_texts(s)) == english
        assert math.pair.value == "1 and 3"
