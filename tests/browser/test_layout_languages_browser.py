"""Long languages fit, in chromium: at 1400x900 and 1024x768, in German, Russian and the
pseudo-locale (each text wrapped and accented: longer than English, as German and Russian are
about 30 % longer), no button, tab or label of the panel is cut (``scrollWidth <= clientWidth``
of the element and of every element inside it), and each row of buttons of the jog panel (the
jog keys ``X −``/``X +`` ..., Increment, Mode, Readout) stays one row: its buttons' boxes share
a top.

One page on one in-process pendant; the language is switched live (``Session.set_language``,
as the selector does), in two states: idle, and with an XYZ 4-point running (its step's buttons
in the Jog tab's dock and in the Calibrate tab). Every tab is shown in turn. The texts come
from the catalogs as they are: German's jog panel is translated, Russian's catalog is still
empty (it shows English until its translators fill it), the pseudo-locale's is complete.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import pytest
import viser

from support.page_barrier import NEXT_FRAMES_JS, Barrier, show_tab
from support.pendant_page import wait_until

pytestmark = pytest.mark.browser

LANGUAGES = ("de", "ru", "qps")
SIZES = ((1400, 900), (1024, 768))

# every visible button, tab and label (and what is inside them) whose content is wider or taller
# than its clipping box, and every button or tab whose label wraps to a second line (viser's
# buttons have a fixed height: a second line is cut off at the bottom)
CUT_JS = """() => {
  const seen = new Set(), cut = [];
  let checked = 0;
  const visible = (e) => e.getClientRects().length > 0 && getComputedStyle(e).visibility !== 'hidden';
  const lines = (e) => {             // the lines its text takes: its text boxes' distinct tops (2 px apart)
    const tops = [], walk = document.createTreeWalker(e, NodeFilter.SHOW_TEXT);
    for (let t = walk.nextNode(); t; t = walk.nextNode()) {
      if (!t.textContent.trim()) continue;
      const r = document.createRange();
      r.selectNodeContents(t);
      for (const b of r.getClientRects()) if (b.width > 0) tops.push(b.top);
    }
    tops.sort((a, b) => a - b);
    return tops.filter((t, i) => i === 0 || t - tops[i - 1] > 2).length;
  };
  for (const root of document.querySelectorAll('button, [role=tab], label')) {
    if (!visible(root)) continue;
    checked += 1;
    const name = `${root.tagName.toLowerCase()} "${(root.innerText || '').trim().slice(0, 80)}"`;
    if (root.matches('button, [role=tab]') && (root.innerText || '').trim() && lines(root) > 1) {
      cut.push(`${name}: its label wraps to ${lines(root)} lines`);
    }
    for (const e of [root, ...root.querySelectorAll('*')]) {
      if (seen.has(e) || !(e instanceof HTMLElement) || !visible(e)) continue;
      seen.add(e);
      const style = getComputedStyle(e), clipsX = style.overflowX !== 'visible' || e === root;
      const clipsY = style.overflowY !== 'visible';
      if (clipsX && e.scrollWidth > e.clientWidth + 1) cut.push(`${name}: ${e.scrollWidth} px wide in ${e.clientWidth} px`);
      else if (clipsY && e.scrollHeight > e.clientHeight + 1) cut.push(`${name}: ${e.scrollHeight} px high in ${e.clientHeight} px`);
    }
  }
  return {cut, checked};
}"""

# the tops of the visible buttons named exactly as given, per name
TOPS_JS = """(names) => {
  const want = new Set(names), out = {};
  for (const b of document.querySelectorAll('button')) {
    const name = (b.innerText || '').trim();
    if (!want.has(name) || b.getClientRects().length === 0) continue;
    (out[name] = out[name] || []).push(b.getBoundingClientRect().top);
  }
  return out;
}"""


def button_groups(view: object) -> Iterator[viser.GuiButtonGroupHandle]:
    """The button groups a view holds (as attributes, or in dicts and lists of them)."""
    for value in vars(view).values():
        items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else (value,)
        yield from (h for h in items if isinstance(h, viser.GuiButtonGroupHandle))


def split_rows(page: Any, session: Any) -> list[str]:
    """The jog panel's visible button groups whose buttons do not share one top."""
    problems = []
    groups = [g for g in button_groups(session.views["pendant"]) if g.visible]
    assert len(groups) >= 7, f"only {[g.label for g in groups]} of the jog panel's rows found"   # Increment, X..C
    for group in groups:
        names = [str(o) for o in group.options]
        tops = page.evaluate(TOPS_JS, names)
        shown = [min(tops[n]) for n in names if n in tops]   # one visible button per name
        if len(shown) != len(names):
            problems.append(f"row {group.label!r}: buttons {names} not all shown ({sorted(tops)})")
        elif max(shown) - min(shown) > 1.0:
            problems.append(f"row {group.label!r} wraps: tops {[round(t) for t in shown]} of {names}")
    return problems


def measure_tabs(page: Any, where: str) -> list[str]:
    """Cut labels and split rows on each tab in turn (``where``: the state, for the messages)."""
    problems = []
    for i in range(page.locator("[role=tab]").filter(visible=True).count()):
        show_tab(page, i)
        out = page.evaluate(CUT_JS)
        assert out["checked"] >= 5, f"{where}, tab {i + 1}: only {out['checked']} buttons and labels found"
        problems += [f"{where}, tab {i + 1}: {c}" for c in out["cut"]]
    show_tab(page, 0)
    return problems


def test_long_languages_cut_no_label_and_wrap_no_jog_row(app_factory, new_page: Callable[..., Any]) -> None:
    app = app_factory()
    page = new_page(app.url)
    wait_until(lambda: len(app.sessions) == 1, "the page's session")
    (s,) = app.sessions.values()
    barrier = Barrier(s)
    problems: list[str] = []
    for state in ("idle", "XYZ 4-point running"):
        if state != "idle":
            s.wizard_commands.start("xyz4")
        for language in LANGUAGES:
            s.set_language(language)
            barrier.sync(page)
            for width, height in SIZES:
                page.set_viewport_size({"width": width, "height": height})
                page.wait_for_function(f"window.innerWidth === {width} && window.innerHeight === {height}")
                page.evaluate(NEXT_FRAMES_JS)          # the panel re-laid out at the new size
                where = f"{language} {width}x{height} {state}"
                problems += [f"{where}: {p}" for p in split_rows(page, s)]
                problems += measure_tabs(page, where)
    assert not problems, "cut labels or wrapped rows:\n" + "\n".join(problems)
