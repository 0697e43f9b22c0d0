"""What a page shows as text, per state, for the pseudo-locale walk: the visible text of the DOM
(one entry per block element, code and pre left out as ``support.pseudo_text.untranslated_words``
leaves out backticks), the placeholders and titles of visible elements, the 3D labels of a
session's scene (drawn on a canvas: read from the server's label handles), the hints of its GUI
controls (shown on hover), the options of its dropdowns, and the notifications it was sent.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import viser

__all__ = ["TEXTS_JS", "gui_hints", "record_notifications", "scene_labels"]

# One string per block-level element holding visible text (inline children joined into it, so a
# ⟦...⟧ span split by <strong> stays whole); text inside <code>/<pre> is a space; then every
# visible element's placeholder and title.
TEXTS_JS = """() => {
  const blocks = new Map(), out = [];
  const inline = (e) => getComputedStyle(e).display === 'inline' && !['BUTTON', 'LABEL'].includes(e.tagName);
  const walk = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
  for (let t = walk.nextNode(); t; t = walk.nextNode()) {
    const parent = t.parentElement;
    if (!parent || !t.textContent.trim() || ['SCRIPT', 'STYLE', 'NOSCRIPT'].includes(parent.tagName)) continue;
    if (!parent.checkVisibility({checkOpacity: true, checkVisibilityCSS: true})) continue;
    let block = parent;
    while (block.parentElement && block !== document.body && inline(block)) block = block.parentElement;
    const text = parent.closest('code, pre') ? ' ' : t.textContent;
    blocks.set(block, (blocks.get(block) || '') + ' ' + text);   // a space: <br> and inline boxes part words
  }
  for (const text of blocks.values()) if (text.trim()) out.push(text.replace(/\\s+/g, ' ').trim());
  for (const e of document.querySelectorAll('[placeholder], [title]')) {
    if (!e.checkVisibility()) continue;
    for (const a of ['placeholder', 'title']) {
      const v = e.getAttribute(a);
      if (v && v.trim()) out.push(v.trim());
    }
  }
  return out;
}"""


def scene_labels(session: Any) -> list[str]:
    """The texts of the visible 3D labels of ``session``'s scene (its viser target)."""
    handles = list(session.target.scene._handle_from_node_name.values())
    return [h.text for h in handles if isinstance(h, viser.LabelHandle) and h.visible and h.text]


def gui_hints(session: Any) -> Iterator[tuple[str, str]]:
    """("hint", text) for the hints (tooltips, shown on hover) and ("option", text) for the
    options of the dropdowns and button groups (a dropdown's list opens on a click) of
    ``session``'s visible GUI controls."""
    for handle in list(session.target.gui._gui_input_handle_from_uuid.values()):
        if not getattr(handle, "visible", True):
            continue
        hint = getattr(handle, "hint", None)
        if isinstance(hint, str) and hint:
            yield "hint", hint
        if isinstance(handle, viser.GuiDropdownHandle):
            yield from (("option", str(o)) for o in handle.options)


def record_notifications(session: Any, into: list[str]) -> None:
    """Append the title and body of every notification ``session`` sends to ``into`` (they are
    still sent to the page)."""
    send = session.notify

    def notify(title: str, body: str = "", *args: Any, **kwargs: Any) -> Any:
        into.extend(t for t in (title, body) if t)
        return send(title, body, *args, **kwargs)

    session.notify = notify
