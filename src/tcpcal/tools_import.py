"""A controller file's tool table brought into the tool library (``tcpcal tools import``).

The entries come from :func:`tcpcal.controllers.parse_tool_file` (docs/formats.md). Rules
(docs/cli.md "tools import"):

* The slot of an entry is its tool number (KUKA ``TOOL_DATA[n]``, FANUC ``UTOOL[n]``,
  Yaskawa ``//TOOL n``). A number outside the library's slots 1..16 (Yaskawa's tool 0 and
  17..63) is not imported: a warning names it. A format without tool numbers (ABB
  ``tooldata``, UR ``set_tcp``) fills the library's free slots in file order.
* Names are kept and checked by :class:`tcpcal.tool.Tool`'s rules (24 printable characters, no
  double quote, ...): a name that breaks them is an error naming the entry. An entry without
  a name is stored as ``tool<n>`` (``<n>`` its tool number, or its place in the file).
* Unused entries (no name, TCP and rotation zero, no load: the empty rows of a Yaskawa
  ``TOOL.CND``) are skipped and counted.
* The load comes along where the file has it (Yaskawa ``TOOL.CND``, ABB ``tload``, KUKA
  ``LOAD_DATA``): mass, centre of gravity, the orientation of its inertia axes and the moments
  of inertia; a part the file does not give stays unset (docs/formats.md "Tool loads").
* Nothing is written unless every entry can be stored: an occupied slot is refused (listing
  the slots) unless ``replace``; the names must stay unique in the library. The change is one
  locked library write (:meth:`tcpcal.library.ToolLibrary.save_many`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tcpcal.controllers import ToolEntry, detect_tool_format, get_format, parse_tool_file
from tcpcal.errors import InvalidInputError, TcpcalError
from tcpcal.library import ToolLibrary
from tcpcal.tool import Tool

__all__ = ["ToolImport", "import_tool_file", "plan_tool_import"]


@dataclass(frozen=True)
class ToolImport:
    """What ``tools import`` stored.

    Attributes:
        format: the controller format the file was read as.
        stored: ``(slot, tool)`` pairs written to the library, slot order.
        skipped_unused: entries skipped as unused (no name, all zero).
        warnings: entries not imported and why (one sentence each).
    """

    format: str
    stored: tuple[tuple[int, Tool], ...]
    skipped_unused: int
    warnings: tuple[str, ...]

    def summary(self, library: Path | str) -> str:
        """Lines for the terminal: one per stored tool, then the skipped count."""
        lines = [f"Imported {len(self.stored)} {self.format} tool"
                 f"{'s' if len(self.stored) != 1 else ''} into {library}"]
        lines += [f"  slot {slot}: {tool.name!r}  TCP {', '.join(f'{v:g}' for v in tool.tcp_mm)}"
                  f" mm" + (f", {tool.mass_kg:g} kg" if tool.mass_kg is not None else "")
                  for slot, tool in self.stored]
        if self.skipped_unused:
            lines.append(f"  ({self.skipped_unused} unused entr"
                         f"{'ies' if self.skipped_unused != 1 else 'y'} skipped)")
        return "\n".join(lines)


def _unused(e: ToolEntry) -> bool:
    return (not e.name and not any(e.tcp_mm) and e.mass_kg is None
            and bool(np.allclose(e.rotation, np.eye(3), atol=1e-12)))


def plan_tool_import(entries: list[ToolEntry], fmt: str, existing: dict[int, Tool],
                     n_slots: int, *, replace: bool = False, where: str = ""
                     ) -> tuple[dict[int, Tool], int, list[str]]:
    """The slots and tools an import would store, the unused count and the warnings.

    Raises:
        InvalidInputError: an invalid name (naming the entry), the same name twice, an
            occupied slot without ``replace`` (listing the slots), no free slot left.
    """
    label = get_format(fmt).label
    source = f"{where} " if where else ""
    plan: dict[int, Tool] = {}
    warnings: list[str] = []
    unused = 0
    numberless: list[tuple[int, ToolEntry]] = []
    for k, e in enumerate(entries, 1):
        if _unused(e):
            unused += 1
            continue
        if e.number is None:
            numberless.append((k, e))
            continue
        if not 1 <= e.number <= n_slots:
            warnings.append(f"{label} tool {e.number} {e.name!r} not imported: the library has "
                            f"slots 1..{n_slots}; add it with 'tcpcal tools add SLOT NAME --xyz "
                            "...' in a slot of your choice")
            continue
        if e.number in plan:
            raise InvalidInputError(f"{source}holds tool {e.number} twice; keep one entry per "
                                    "tool number")
        plan[e.number] = _tool(e, e.name or f"tool{e.number}", label, where, f"tool {e.number}")
    free = [s for s in range(1, n_slots + 1) if s not in existing and s not in plan]
    if len(numberless) > len(free):
        raise InvalidInputError(f"{source}has {len(numberless)} tools without a tool number but "
                                f"the library has {len(free)} free slots; remove tools first")
    for slot, (k, e) in zip(free, numberless):
        plan[slot] = _tool(e, e.name or f"tool{k}", label, where, f"entry {k}")
    occupied = sorted(s for s in plan if s in existing)
    if occupied and not replace:
        held = ", ".join(f"{s} ({existing[s].name!r})" for s in occupied)
        raise InvalidInputError(f"slot{'s' if len(occupied) != 1 else ''} {held} of the library "
                                f"{'are' if len(occupied) != 1 else 'is'} occupied; add "
                                "--replace to overwrite them, or remove them first (nothing "
                                "was imported)")
    names: dict[str, int] = {}
    for slot in sorted(plan):
        name = plan[slot].name
        if name in names:
            raise InvalidInputError(f"{source}has two tools named {name!r} (slots {names[name]} "
                                    f"and {slot}); tool names in the library are unique: "
                                    "rename one on the controller")
        names[name] = slot
    for slot, tool in existing.items():
        if slot not in plan and tool.name in names:
            raise InvalidInputError(f"{tool.name!r} is already in slot {slot} of the library; "
                                    "rename or remove it there first (nothing was imported)")
    return plan, unused, warnings


def _tool(e: ToolEntry, name: str, label: str, where: str, what: str) -> Tool:
    note = f"imported from {Path(where).name or 'a controller file'} ({label} {what})"
    try:
        known = e.mass_kg is not None
        return Tool.from_rotation(name, e.tcp_mm, e.rotation, mass_kg=e.mass_kg,
                                  cog_mm=e.cog_mm if known else None,
                                  load_abc_deg=e.load_abc_deg if known else None,
                                  inertia_kgm2=e.inertia_kgm2 if known else None, notes=note)
    except TcpcalError as exc:
        raise InvalidInputError(f"{label} {what} {e.name!r} cannot be stored: "
                                f"{' '.join(str(exc).split())} (rename it on the controller, "
                                "or add it with 'tcpcal tools add')") from None


def import_tool_file(library: ToolLibrary, text: str, fmt: str = "auto", *,
                     filename: str | None = None, replace: bool = False,
                     where: str = "") -> ToolImport:
    """Read the tool table of ``text`` into ``library`` (the rules of the module docstring).

    Raises:
        InvalidInputError: unreadable file (:class:`tcpcal.controllers.ControllerFileError`),
            or an entry that cannot be stored (nothing is written then).
        tcpcal.library.ToolLibraryError: the library file cannot be written.
    """
    name = detect_tool_format(text, filename) if fmt == "auto" else fmt
    entries = parse_tool_file(text, name)
    found: dict[str, tuple[int, list[str]]] = {}

    def plan(existing: dict[int, Tool]) -> dict[int, Tool]:
        tools, unused, warnings = plan_tool_import(entries, name, existing, library.N_SLOTS,
                                                   replace=replace, where=where)
        found["extra"] = (unused, warnings)
        return tools

    stored = library.save_many(plan)
    unused, warnings = found["extra"]
    return ToolImport(name, tuple(sorted(stored.items())), unused, tuple(warnings))
