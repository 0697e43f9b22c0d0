"""The numeric tool entry's live preview: what Save would store, field by field."""

from __future__ import annotations

import pytest

from tcp_pendant.pendant.tool_entry import FIELDS, ToolEntry, entry_preview_markdown
from tcp_pendant.text_escape import escape_markdown

pytestmark = pytest.mark.shares_cpu  # asserts no time, latency or load (tests/conftest.py)


def _entry(name: str = "Pen", **vals: str) -> ToolEntry:
    base = dict.fromkeys(FIELDS, "0")
    base.update(vals)
    return ToolEntry(name, base)


def test_valid_entry_previews_the_numbers_it_will_store() -> None:
    text = entry_preview_markdown(_entry(X="12,5", Y="-3", Z="100", B="90", C="-0.0001"))
    # decimal comma read as a point, two decimals, -0.00 shown as 0.00
    assert "**Pen** · X 12.50 Y -3.00 Z 100.00 mm · A 0.00 B 90.00 C 0.00 deg" in text
    assert text.endswith("✔ ready to save")


def test_invalid_fields_show_a_question_mark_and_the_reason() -> None:
    text = entry_preview_markdown(_entry(name=" ", Z="1o0", A="400"))
    assert "*(no name)* · X 0.00 Y 0.00 Z ? mm · A ? B 0.00 C 0.00 deg" in text
    assert escape_markdown("Z (mm): '1o0' is not a number") in text      # the reasons as text
    assert escape_markdown("A (deg): 400 is out of range") in text
    assert "Name: enter a tool name" in text
    assert "ready to save" not in text
