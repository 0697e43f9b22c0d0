"""Small owners in the app: no class of ``app/tcp_pendant`` spans more than
:data:`MAX_CLASS_LINES` lines, and no function or method more than :data:`MAX_FUNCTION_LINES`
unless a line of its docstring starts with "Long because" (the reason it is not split).

Every module is parsed with :mod:`ast`; a definition's lines run from its first decorator (or its
``def`` / ``class`` line) to its last line, blank lines and comments included. A definition is
named ``<module file stem>:<qualified name>`` (``session:Session``, ``pendant_panel:PendantPanel.__init__``).

A class or function over its limit fails :func:`test_no_class_is_over_the_limit` /
:func:`test_no_function_is_over_the_limit`, which name it, where, and its lines.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cache
from pathlib import Path

APP = Path(__file__).resolve().parents[2] / "app" / "tcp_pendant"
MAX_CLASS_LINES = 500
MAX_FUNCTION_LINES = 80
JUSTIFIED = "Long because"
"""A docstring line starting with this states why a function is over :data:`MAX_FUNCTION_LINES`."""



@dataclass(frozen=True)
class Definition:
    """A class or function of the app: ``name`` (``stem:qualname``), where, and its lines."""

    name: str
    where: str
    lines: int
    is_class: bool
    justified: bool


def _definitions_in(tree: ast.AST, stem: str, where: str) -> list[Definition]:
    out: list[Definition] = []

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                first = min([child.lineno, *(d.lineno for d in child.decorator_list)])
                assert child.end_lineno is not None
                doc = ast.get_docstring(child) or ""
                out.append(Definition(
                    name=f"{stem}:{prefix}{child.name}", where=f"{where}:{child.lineno}",
                    lines=child.end_lineno - first + 1, is_class=isinstance(child, ast.ClassDef),
                    justified=any(line.strip().startswith(JUSTIFIED) for line in doc.splitlines())))
                visit(child, f"{prefix}{child.name}.")
            else:
                visit(child, prefix)

    visit(tree, "")
    return out


@cache
def definitions() -> tuple[Definition, ...]:
    """Every class and function (methods and nested ones included) of ``app/tcp_pendant``."""
    found: list[Definition] = []
    for path in sorted(APP.rglob("*.py")):
        where = str(path.relative_to(APP.parent))
        found += _definitions_in(ast.parse(path.read_text(encoding="utf-8"), where), path.stem, where)
    return tuple(found)


def _big_classes() -> dict[str, Definition]:
    return {d.name: d for d in definitions() if d.is_class and d.lines > MAX_CLASS_LINES}


def _long_functions() -> dict[str, Definition]:
    return {d.name: d for d in definitions()
            if not d.is_class and d.lines > MAX_FUNCTION_LINES and not d.justified}


def _listed(offenders: dict[str, Definition]) -> str:
    return "; ".join(f"{d.name} ({d.where}, {d.lines} lines)" for d in offenders.values())


def test_the_app_is_parsed() -> None:
    names = {d.name for d in definitions()}
    assert "gradebook:Gradebook" in names and len(names) > 500


def test_no_class_is_over_the_limit() -> None:
    new = _big_classes()
    assert not new, f"classes over {MAX_CLASS_LINES} lines: {_listed(new)}"


def test_no_function_is_over_the_limit() -> None:
    new = _long_functions()
    assert not new, (f"functions over {MAX_FUNCTION_LINES} lines without a docstring line starting "
                     f"{JUSTIFIED!r}: {_listed(new)}")
