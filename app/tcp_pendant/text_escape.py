"""Text a user controls, made safe to put into viser markdown: it is shown literally, never run.

viser renders ``add_markdown`` content in the browser with react-markdown + remark-gfm and a
``rehypeRawDom`` plugin that passes raw HTML through the browser's own parser *without any
sanitising* (viser/client/src/Markdown.tsx). So a tool name such as ``<style>*{opacity:0}`` would
restyle the whole page, ``![](//host/x)`` would make the browser fetch a URL and ``[a](//evil)``
would become a live link. Every view that puts user text (tool names and notes, typed names,
upload file names, the content of a loaded session record, error messages quoting input) into
markdown passes that text through :func:`escape_markdown` where the markdown is composed.

Rules of :func:`escape_markdown`:

* the five HTML-significant characters become entities (``&amp; &lt; &gt; &quot; &#39;``), so
  the output never holds a raw ``<`` and react-markdown never sees raw HTML;
* every ASCII punctuation character that can start markdown syntax (``\\ ` * _ [ ] ( ) # + - . !
  | { } ~ =``) gets a backslash (CommonMark then shows the character itself): no emphasis,
  link, image, code span, heading, list, table cell border (``|``) or strikethrough can start
  inside user text;
* GFM's *autolink literals* (``www.host``, ``http://``, ``https://``, ``user@host``) are found by
  remark-gfm in the text *after* escapes are resolved, so backslashes do not stop them; a WORD
  JOINER (U+2060, invisible and zero-width) is inserted after ``www``/``http``/``https`` and
  after ``@`` so that no bare URL or e-mail address becomes a link;
* line breaks (``\\r``, ``\\n`` and the Unicode line separators) are folded to one space: the text
  is one line, safe inside a paragraph, a bold span or a GFM table cell; a leading blank becomes
  an entity, so the text cannot start an indented code block.

The result is meant for ordinary markdown text (paragraphs, ``**bold**``, table cells), not for
the inside of a code span (backticks show entities and backslashes literally).
"""

from __future__ import annotations

import re

__all__ = ["WORD_JOINER", "escape_html", "escape_markdown", "escape_markdown_lines"]

WORD_JOINER = "\u2060"
"""Invisible, zero-width character that breaks GFM's autolink-literal patterns."""

_HTML_ENTITIES = {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;"}

# The ASCII punctuation that can start markdown syntax (CommonMark lets a backslash precede any
# ASCII punctuation and then shows the character itself): images and links ``! [ ] ( )``,
# emphasis and code spans (``*``, ``_``, backtick), headings ``#``, list items and rules ``- + . =``, GFM tables
# ``|`` and strikethrough ``~``, the backslash itself and ``{ }``. The HTML five are entities
# instead; ``: / @ , ; ? $ % ^`` mean nothing in remark-gfm's markdown and stay as they are
# (bare links are broken with a WORD JOINER, see ``_AUTOLINK_STARTS``).
_BACKSLASHED = frozenset("!#()*+-.=[\\]_`{|}~")

# Line endings of markdown plus the Unicode line/paragraph separators and NEL.
_LINE_BREAKS = re.compile("\r\n|[\r\n\u0085\u2028\u2029\x0b\x0c]")

# GFM autolink literals: ``www.``, ``http:``/``https:`` and the ``@`` of an e-mail address.
_AUTOLINK_STARTS = re.compile(r"(?i)www(?=\.)|https?(?=:)|@")


def _break_autolinks(text: str) -> str:
    return _AUTOLINK_STARTS.sub(lambda m: m.group(0) + WORD_JOINER, text)


def escape_html(text: str) -> str:
    """Escape the five HTML-significant characters ``& < > " '`` as entities.

    Args:
        text: Any text.

    Returns:
        The text with ``&``, ``<``, ``>``, ``"`` and ``'`` as ``&amp; &lt; &gt; &quot; &#39;``.
    """
    return "".join(_HTML_ENTITIES.get(c, c) for c in text)


def escape_markdown(text: str) -> str:
    """Make user text show literally, on one line, in viser markdown (and in GFM table cells).

    Args:
        text: The user's text (a tool name, note, file name, ...). Anything else that reaches
            here (a number from a loaded record) is converted with ``str()``; ``None`` gives ``""``.

    Returns:
        Markdown that renders as exactly ``text`` (line breaks folded to spaces, a zero-width
        WORD JOINER inside would-be bare links), with no raw ``<`` and no markdown syntax.
    """
    if text is None:
        return ""
    s = _break_autolinks(_LINE_BREAKS.sub(" ", str(text)))
    out = []
    if s[:1] in (" ", "\t"):     # as an entity, leading blanks cannot indent a code block
        out.append(f"&#{ord(s[0])};")
        s = s[1:]
    for c in s:
        entity = _HTML_ENTITIES.get(c)
        if entity is not None:
            out.append(entity)
        elif c in _BACKSLASHED:
            out.append("\\" + c)
        else:
            out.append(c)
    return "".join(out)


def escape_markdown_lines(text: str) -> str:
    """User text of several lines (a trainer's instructions or message) as markdown
    paragraphs: each non-blank line through :func:`escape_markdown`, one paragraph per line.

    Args:
        text: the user's text; its line breaks separate the paragraphs.

    Returns:
        Markdown with no raw ``<`` and no markdown syntax, a paragraph per line of ``text``.
    """
    lines = _LINE_BREAKS.split("" if text is None else str(text))
    return "\n\n".join(escape_markdown(line) for line in lines if line.strip())
