"""A griffe extension for the documentation site (mkdocs.yml): Sphinx roles in docstrings as code.

The docstrings name other objects the Sphinx way, ``:func:`update_caption```,
``:class:`~tcp_pendant.session.Session```, which Markdown would show with the role's colons.
This extension rewrites each role to inline code as it is loaded: the target as written, or its
last part when the target starts with ``~`` (Sphinx's short form). Text in double backticks is
already code in Markdown and stays as it is.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|meth|class|mod|data|attr|obj|exc|const|ref):`(~?)([^`<]*?)(?:\s*<[^`>]*>)?`")


def as_code(match: re.Match[str]) -> str:
    """The role's target as inline code (its last part for the ``~`` form)."""
    short, target = match.group(1), match.group(2).strip()
    if short:
        target = target.rsplit(".", 1)[-1]
    return f"`{target}`"


def without_roles(text: str) -> str:
    """``text`` with every Sphinx role written as inline code."""
    return ROLE.sub(as_code, text)


class SphinxRolesAsCode(griffe.Extension):
    """Rewrites the Sphinx roles of every docstring as it is loaded."""

    def on_instance(self, *, node: Any, obj: griffe.Object, agent: Any, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = without_roles(obj.docstring.value)
