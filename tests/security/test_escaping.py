"""Everything users type is shown as text, everywhere (the escaping helper).

``tcp_pendant.text_escape.escape_markdown`` turns user text into markdown that renders as
exactly that text in viser (whose markdown passes raw HTML unsanitised and autolinks bare
URLs). These tests check its output as text (no raw ``<``, every markdown character escaped)
and as rendered by a CommonMark renderer (markdown-it-py, installed with viser's ``rich``):
one paragraph holding the literal text, no element but ``<p>``. The browser tests
(test_escaping_browser.py) check the same in chromium with viser's own renderer.
"""

from __future__ import annotations

import html
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from markdown_it import MarkdownIt
from tcp_pendant.text_escape import WORD_JOINER, escape_html, escape_markdown

# The payloads of the issue, and a few more of the same kinds.
STYLE = "<style>*{opacity:0}"
IMAGE = "![](//127.0.0.1:8/x)"
LINK = "[click](//evil)"
IFRAME = """<iframe srcdoc="<img src=x onerror=parent.document.title='pwned'>">.json"""
PAYLOADS = [
    STYLE, IMAGE, LINK, IFRAME,
    "<img src=x onerror=alert(1)>", "<script>alert(1)</script>", "<a href=//evil>x</a>",
    "**bold** _em_ `code` ~~del~~", "# heading", "- item", "1. item", "> quote", "---",
    "| a | b |", "a|b", "[ref]: //evil", "[x][ref]", "<https://evil.example>", "www.evil.example",
    "http://evil.example/x", "HTTPS://EVIL.EXAMPLE", "mailto:a@evil.example", "me@evil.example",
    "&lt;style&gt;", "&#60;b&#62;", "back\\slash\\", "{curly}", "a\nb\r\nc\rd", "line\u2028sep",
    "    indented code", "\\<b>", "![alt](data:image/png;base64,AAAA)", "[^1]", "- [ ] task",
]

# CommonMark + GFM tables and strikethrough, raw HTML on (as viser renders it); markdown-it-py
# has no autolink literals without the linkify plugin: the word joiner is checked directly.
_MD = MarkdownIt("commonmark", {"html": True}).enable(["table", "strikethrough"])


def rendered(md: str) -> str:
    return _MD.render(md)


def unescape(md: str) -> str:
    """Read escape_markdown's output back: backslash escapes, entities, word joiners."""
    return re.sub(r"\\(.)|&(amp|lt|gt|quot|#\d+);|" + WORD_JOINER,
                  lambda m: m.group(1) or (html.unescape(m.group(0)) if m.group(2) else ""), md)


def folded(text: str) -> str:
    return re.sub("\r\n|[\r\n\u0085\u2028\u2029\x0b\x0c]", " ", text)


@pytest.mark.parametrize("text", PAYLOADS)
def test_each_payload_renders_as_one_paragraph_of_its_literal_text(text: str) -> None:
    md = escape_markdown(text)
    assert "<" not in md and ">" not in md and "\n" not in md and "\r" not in md
    out = rendered(md)
    # one paragraph; nothing else (no <style>, <img>, <a>, <iframe>, <code>, <h1>, <li>, <table> ...)
    assert re.fullmatch(r"<p>[^<]*</p>\n", out), out
    shown = html.unescape(out[3:-5]).replace(WORD_JOINER, "")
    assert shown == folded(text).rstrip(" ")          # a paragraph drops trailing blanks only


def test_the_attack_payloads_exactly() -> None:
    assert escape_markdown(STYLE) == r"&lt;style&gt;\*\{opacity:0\}"
    assert escape_markdown(IMAGE) == r"\!\[\]\(//127\.0\.0\.1:8/x\)"
    assert escape_markdown(LINK) == r"\[click\]\(//evil\)"
    assert escape_markdown(IFRAME) == (r"&lt;iframe srcdoc\=&quot;&lt;img src\=x onerror\=parent\.document\.title"
                                       r"\=&#39;pwned&#39;&gt;&quot;&gt;\.json")


def test_bare_links_get_a_word_joiner_so_gfm_does_not_autolink_them() -> None:
    # remark-gfm finds www., http(s):// and e-mail addresses in the text after escapes are
    # resolved, so only a character between the parts stops it
    assert escape_markdown("see www.evil.example") == f"see www{WORD_JOINER}\\.evil\\.example"
    assert escape_markdown("HTTPS://x") == f"HTTPS{WORD_JOINER}://x"
    assert escape_markdown("http://x") == f"http{WORD_JOINER}://x"
    assert escape_markdown("a@b.example") == f"a@{WORD_JOINER}b\\.example"
    assert WORD_JOINER not in escape_markdown("Torch 2: wwwx, httpx, a.b")


def test_plain_names_stay_readable_and_nothing_is_escaped_twice() -> None:
    assert escape_markdown("Pointer") == "Pointer"
    assert escape_markdown("Torch 2: 45° bent") == "Torch 2: 45° bent"
    assert escape_markdown("Pen 4P") == "Pen 4P"
    once = escape_markdown("a<b")
    assert escape_markdown(once) != once            # escaping is not idempotent: escape once, where composed
    assert unescape(escape_markdown(once)) == once


def test_table_cells_keep_their_pipes_inside() -> None:
    md = "| name | slot |\n|---|---|\n| " + escape_markdown("a | b || c") + " | 1 |"
    out = rendered(md)
    assert out.count("<td>") == 2 and "<td>a | b || c</td>" in out


def test_newlines_are_folded_so_user_text_cannot_start_a_block() -> None:
    md = "**Loaded " + escape_markdown("x\n\n# big\n<style>*{opacity:0}</style>") + "**"
    out = rendered(md)
    assert "<h1>" not in out and "<style>" not in out and out.startswith("<p><strong>")


def test_escape_html_covers_the_five() -> None:
    assert escape_html("""<a href="x" title='y'>&</a>""") == \
        "&lt;a href=&quot;x&quot; title=&#39;y&#39;&gt;&amp;&lt;/a&gt;"


def test_none_and_numbers_from_a_loaded_record_do_not_crash() -> None:
    assert escape_markdown(None) == ""                  # type: ignore[arg-type]
    assert escape_markdown(3.5) == r"3\.5"              # type: ignore[arg-type]


@settings(max_examples=400, deadline=None)
@given(st.text(alphabet=st.characters(blacklist_characters=WORD_JOINER), max_size=60))
def test_property_no_raw_angle_bracket_and_reads_back_to_the_text(text: str) -> None:
    md = escape_markdown(text)
    assert "<" not in md and ">" not in md and "\n" not in md and "\r" not in md
    assert unescape(md) == folded(text)
    # every markdown-significant character is escaped (read left to right, a backslash takes
    # the next character)
    i = 0
    while i < len(md):
        if md[i] == "\\":
            i += 2
            continue
        entity = re.match(r"&(amp|lt|gt|quot|#\d+);", md[i:])
        if entity:
            i += len(entity.group(0))
            continue
        assert md[i] not in "!#()*+-.=[]_`{|}~", (md, i)
        i += 1


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=st.sampled_from(list("<>&\"'!#()*+-.=[]_`{|}~\\:/@ aw1hpt\n")), max_size=40))
def test_property_rendered_by_commonmark_it_is_one_paragraph_of_text(text: str) -> None:
    out = rendered(escape_markdown(text))
    if not text.strip(" \n"):
        return                                          # blanks only: an empty document
    assert re.fullmatch(r"<p>[^<]*</p>\n", out), (text, out)
    shown = html.unescape(out[3:-5]).replace(WORD_JOINER, "")
    assert shown == folded(text).rstrip(" ")
