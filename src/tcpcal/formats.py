"""Tool data as robot controllers write it (methods.md section 6).

``export_tool(tool, fmt, slot=1)`` writes one tool as text; ``import_tool(text, fmt, name=None)``
reads it back. Formats (positions in mm unless noted, angles in degrees unless noted; every
rotation conversion goes through ``scipy.spatial.transform.Rotation``):

``kuka``
    As in a KUKA ``$config.dat``::

        TOOL_DATA[1]={X 12.5,Y 0.0,Z 180.25,A 0.0,B -90.0,C 0.0}
        TOOL_NAME[1,]="gripper"

    ``R = Rz(A) Ry(B) Rx(C)`` = ``from_euler("ZYX", [A, B, C])``. A, B, C are written exactly as
    stored in the tool. Import accepts a surrounding declaration (``DECL FRAME TOOL_DATA[1]=...``),
    any whitespace, lower case, and reads ``TOOL_NAME[n,]`` of the same index if present and
    ``LOAD_DATA[n]={M ..,CM {..},J {..}}`` for the load (``M`` <= 0, e.g. KUKA's default -1,
    means none; docs/formats.md "Tool loads"). The text does not write ``LOAD_DATA`` (the
    ``$config.dat`` file of ``tools export --file`` does).
``abb``
    A RAPID ``tooldata`` declaration::

        PERS tooldata gripper:=[TRUE,[[12.5,0,180.25],[q1,q2,q3,q4]],
                                [mass,[0,0,0.001],[1,0,0,0],0,0,0]];

    (written on one line).

    ``q1`` is the scalar part, written with ``q1 >= 0``. ABB requires a positive mass: the tool's
    ``mass_kg`` or, when unknown, :data:`ABB_DEFAULT_MASS_KG` = 0.001 kg with the centre of
    gravity ``[0, 0, 0.001]`` (the load of ABB's ``tool0``); import maps exactly that load back
    to ``mass_kg=None``. A known load is written as the tool holds it (``cog_mm``, the inertia
    axes ``load_abc_deg`` as the ``aom`` quaternion, the moments ``inertia_kgm2``; an unknown
    part as ``[0,0,0.001]``, ``[1,0,0,0]``, ``0,0,0``) and read back so (docs/formats.md "Tool
    loads"): identify the real load data on the controller before moving fast. The identifier is the
    tool name with every character that is not an ASCII letter, digit or ``_`` replaced by ``_``
    (and a leading ``t`` if it does not start with a letter or is a RAPID reserved word such as
    ``IF`` or ``TRUE``): a tcpcal name (at most 24 characters) always gives a valid identifier of
    at most 25 of RAPID's 32. Import accepts ``PERS``/``CONST``/``VAR``/
    ``TASK PERS`` declarations or the bare aggregate ``[TRUE,[[...],[...]],[...]]``; it rejects
    ``robhold`` FALSE (a stationary tool has its frame in WORLD, not FLANGE).
``fanuc``
    The tool frame as FANUC's *Tool Frame / Direct Entry* screen shows it::

        UTOOL[1] Direct Entry
        Comment: gripper
        X: 12.5
        Y: 0.0
        Z: 180.25
        W: 0.0
        P: -90.0
        R: 0.0

    ``R = Rz(R) Ry(P) Rx(W)`` (fixed axes) = ``from_euler("xyz", [W, P, R])``. Import finds
    ``X``, ``Y``, ``Z``, ``W``, ``P``, ``R`` each once, with ``:``, ``=`` or a space, one per
    line or all on one line (e.g. a ``$MNUTOOL`` dump ``X: 12.5 Y: 0.0 ...``); the name comes
    from a ``Comment:`` line if present. FANUC frame comments hold 16 characters on the
    pendant: export writes the first :data:`FANUC_COMMENT_LENGTH` (16) characters of the name
    (trailing spaces dropped).
``ur``
    Universal Robots URScript::

        set_tcp(p[0.0125, 0.0, 0.18025, 0.0, -1.5707963267948966, 0.0])

    metres and a rotation vector in radians (``Rotation.from_rotvec``). Import accepts the pose
    alone (``p[...]`` or ``[...]``) or inside any statement.
``matrix``
    ``T_flange_tool`` as 4 lines of 4 numbers (row-major, translation in mm). Import accepts
    any separators (spaces, commas, brackets) and ``#`` comments, 16 numbers (or 12: the top 3x4),
    checks the last row is ``0 0 0 1`` and the rotation is orthonormal within 1e-6.

Numbers are written with Python's shortest round-trip representation (``repr``), so a round
trip returns the same frame to better than 1e-9 (a real KUKA controller writes fewer digits;
import accepts any). Values smaller than 1e-13 in magnitude (floating-point noise of the
rotation conversions) are written as 0. Only the frame, the name and (ABB) the load travel
through a format (KUKA: the load, on import); notes and calibration records do not.

Where the code lives: each format is one module of :mod:`tcpcal.controllers` (``kuka.py``,
``abb.py``, ``fanuc.py``, ``ur.py``, ``matrix.py``) whose ``FORMAT`` declares its
``render_text``/``parse_text``; this module only dispatches through
:data:`tcpcal.controllers.REGISTRY` (docs/architecture.md "Controller formats"). :data:`FORMATS`
is the live tuple of the registered formats that have a tool data text.

Import names: ``name=`` if given, else the name found in the text (KUKA ``TOOL_NAME``, ABB
identifier, FANUC ``Comment``), else ``tool<n>`` (KUKA), ``utool<n>`` (FANUC), ``ur_tcp``,
``imported``. Errors are :class:`tcpcal.errors.InvalidInputError` naming the format and what
could not be parsed.
"""

from __future__ import annotations

from collections.abc import Sequence

from tcpcal.controllers import REGISTRY, ControllerFormat, _Names
from tcpcal.controllers.abb import DEFAULT_MASS_KG as ABB_DEFAULT_MASS_KG
from tcpcal.controllers.fanuc import COMMENT_LENGTH as FANUC_COMMENT_LENGTH
from tcpcal.errors import InvalidInputError
from tcpcal.tool import Tool

__all__ = ["ABB_DEFAULT_MASS_KG", "FANUC_COMMENT_LENGTH", "FORMATS", "export_tool", "import_tool",
           "text_format"]

FORMATS: Sequence[str] = _Names(lambda f: f.has_text)
"""Names of the formats with a tool data text, in menu order (``kuka``, ``abb``, ``fanuc``,
``ur``, ``matrix`` and any format registered later); compares equal to that tuple."""


def text_format(fmt: object) -> ControllerFormat:
    """The registered format ``fmt`` that has a tool data text.

    Raises:
        InvalidInputError: no such format (the message lists the ones there are).
    """
    found = REGISTRY.get(fmt) if isinstance(fmt, str) else None
    if found is None or not found.has_text:
        raise InvalidInputError(f"unknown tool format {fmt!r}; use one of {', '.join(FORMATS)}.")
    return found


def export_tool(tool: Tool, fmt: str, *, slot: int = 1) -> str:
    """Write ``tool`` as the controller ``fmt`` does (module docstring), ending in a newline.

    Args:
        tool: the tool.
        fmt: one of :data:`FORMATS`.
        slot: the controller's tool number where the format has them (``kuka`` 1..16,
            ``fanuc`` 1..10: ``ControllerFormat.tool_numbers``); ignored otherwise.

    Raises:
        InvalidInputError: unknown format, bad slot, not a Tool.
    """
    f = text_format(fmt)
    if not isinstance(tool, Tool):
        raise InvalidInputError(f"export_tool needs a tcpcal.Tool, got {type(tool).__name__}.")
    return f.render_text(tool, slot)  # type: ignore[misc]


def import_tool(text: str, fmt: str, *, name: str | None = None) -> Tool:
    """Read one tool written in controller format ``fmt`` (module docstring).

    Args:
        text: the controller text (surrounding lines and whitespace are tolerated).
        fmt: one of :data:`FORMATS`.
        name: name of the tool; default: the name in the text, else a default per format.

    Returns:
        The tool; rotations are converted to KUKA A, B, C (``Tool.abc_deg``).

    Raises:
        InvalidInputError: unknown format, or text that cannot be parsed (the message names
            the format and the part that failed).
    """
    f = text_format(fmt)
    if not isinstance(text, str):
        raise InvalidInputError(f"{fmt}: import_tool needs the text as a string, got {text!r}.")
    return f.parse_text(text, name)  # type: ignore[misc]
