"""Physical tools (with their hidden true TOOL frame), the reference tip, and the built-in robots.

A tool is a URDF fragment whose root link ``tool_mount`` is bolted to the robot's ``flange``
(same frame) and whose link ``tcp`` is the tool's **true TOOL frame**: origin at the true TCP,
X along the working direction (KUKA, methods.md section 1). ``T_flange_tool_true`` is read from
the URDF with yourdfpy, so the URDF is the one source of truth for both the drawing and the
hidden answer the trainee's calibration is graded against.

The reference tip is a URDF whose root link ``stand_base`` stands on the floor and whose link
``tip`` is at the spike point; the app places the stand so that ``tip`` is at the controller's
``reference_tip_world_m``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import yourdfpy

from tcp_pendant.controller.assets import REFERENCE_TIP_URDF, ROBOT_URDFS, TOOL_URDFS, asset_path, robots_dir
from tcp_pendant.controller.errors import ControllerError
from tcp_pendant.translation import ENGLISH, N_, Translator
from tcpcal.tool import Tool
from tcpcal.validation import read_only_array

__all__ = [
    "TOOL_LABELS",
    "ReferenceTipModel",
    "T_flange_tool_m",
    "ToolModel",
    "builtin_robots",
    "builtin_tools",
    "load_tool",
    "reference_tip_model",
    "shown_tool_label",
    "urdf_transform",
]

TOOL_LABELS: dict[str, str] = {
    "pointer": N_("Straight pointer"),
    "torch": N_("Bent-neck welding torch"),
    "gripper": N_("Two-finger gripper"),
}
"""The built-in tools' labels. A label is also the name a calibration of that tool is saved
under by default, so each one passes ``tcpcal.tool``'s name check (at most
``tcpcal.tool.MAX_NAME_LENGTH`` = 24 characters, no double quote). English: shown in the reader's
language by :func:`shown_tool_label`; a saved name stays as it was saved (data)."""


def shown_tool_label(label: str, tr: Translator = ENGLISH, *, in_sentence: bool = False) -> str:
    """A tool model's ``label`` as a pendant shows it, in ``tr``'s language (a label the
    catalogs do not hold, e.g. a tool file's own, as it is). ``in_sentence``: inside a sentence
    ("Mount the straight pointer"): an untranslated label in lower case, as English writes it;
    a translation as its translator wrote it (German nouns keep their capital)."""
    said = tr.gettext(label)
    return said.lower() if in_sentence and said == label else said


def T_flange_tool_m(tool: Tool) -> np.ndarray:
    """Tool data (``tcpcal.Tool``: TCP in mm, A, B, C) as the app's ``T_flange_tool`` (4, 4,
    metres), a new array."""
    T = np.array(tool.T_flange_tool_mm, dtype=float)
    T[:3, 3] /= 1000.0
    return T


@dataclass(frozen=True, eq=False)
class ToolModel:
    """A physical tool: what is bolted on the flange.

    Attributes:
        key: "pointer" | "torch" | "gripper" (or the key given to :func:`load_tool`).
        label: name shown to the user.
        urdf_path: the tool's URDF (root link ``tool_mount`` = FLANGE frame).
        T_flange_tool_true: (4,4) true TOOL frame in FLANGE coordinates, metres; hidden from
            the trainee (read-only array).
    """

    key: str
    label: str
    urdf_path: Path
    T_flange_tool_true: np.ndarray

    def __post_init__(self) -> None:
        T = np.asarray(self.T_flange_tool_true, dtype=float)
        if T.shape != (4, 4) or not np.all(np.isfinite(T)):
            raise ControllerError(f"Tool {self.key!r}: T_flange_tool_true must be a finite 4x4 "
                                  f"matrix, got shape {T.shape}.")
        R = T[:3, :3]
        if np.abs(R.T @ R - np.eye(3)).max() > 1e-9 or np.linalg.det(R) < 0:
            raise ControllerError(f"Tool {self.key!r}: T_flange_tool_true has no proper rotation.")
        object.__setattr__(self, "T_flange_tool_true", read_only_array(T))
        object.__setattr__(self, "urdf_path", Path(self.urdf_path))

    def __repr__(self) -> str:
        return f"ToolModel(key={self.key!r}, label={self.label!r}, urdf_path={str(self.urdf_path)!r})"


def urdf_transform(urdf_path: Path, frame_from: str, frame_to: str) -> np.ndarray:
    """``T_from_to`` (4,4, metres) between two links of a URDF of fixed joints, via yourdfpy.

    Raises:
        ControllerError: unreadable file or missing link.
    """
    try:
        urdf = yourdfpy.URDF.load(str(urdf_path), load_meshes=False, build_collision_scene_graph=False,
                                  load_collision_meshes=False)
    except Exception as exc:
        raise ControllerError(f"yourdfpy cannot load {urdf_path}: {exc}") from exc
    for link in (frame_from, frame_to):
        if link not in urdf.link_map:
            raise ControllerError(f"{Path(urdf_path).name} has no link {link!r} (links: "
                                  f"{', '.join(urdf.link_map)}).")
    return np.array(urdf.get_transform(frame_to=frame_to, frame_from=frame_from), dtype=float)


def load_tool(urdf_path: Path | str, *, key: str | None = None, label: str | None = None,
              mount_link: str = "tool_mount", tcp_link: str = "tcp") -> ToolModel:
    """A :class:`ToolModel` from a tool URDF: ``T_flange_tool_true`` = pose of ``tcp_link`` in
    ``mount_link`` (the mount link is the FLANGE frame)."""
    path = Path(urdf_path)
    if not path.is_file():
        raise ControllerError(f"Tool URDF not found: {path}.")
    key = path.stem if key is None else key
    return ToolModel(key=key, label=TOOL_LABELS.get(key, key) if label is None else label,
                     urdf_path=path, T_flange_tool_true=urdf_transform(path, mount_link, tcp_link))


@lru_cache(maxsize=4)
def _builtin_tools(root: Path) -> tuple[ToolModel, ...]:
    return tuple(load_tool(asset_path(rel), key=key) for key, rel in TOOL_URDFS.items())


def builtin_tools() -> dict[str, ToolModel]:
    """The built-in tools by key: "pointer", "torch", "gripper" (from ``robots/tools``)."""
    return {t.key: t for t in _builtin_tools(robots_dir())}


def builtin_robots() -> dict[str, Path]:
    """The built-in robots: "kr6" (KUKA KR 6 R900 sixx), "gp12" (Yaskawa GP12 class) -> URDF."""
    return {key: robots_dir() / rel for key, rel in ROBOT_URDFS.items()}


@dataclass(frozen=True, eq=False)
class ReferenceTipModel:
    """The reference tip (a spike on a stand).

    Attributes:
        urdf_path: its URDF (root ``stand_base``, link ``tip`` at the spike point).
        T_stand_tip: (4,4) pose of the spike point in the stand's root frame, metres.
    """

    urdf_path: Path
    T_stand_tip: np.ndarray

    def T_world_stand(self, tip_world_m: np.ndarray) -> np.ndarray:
        """Where to draw the stand so that its spike is at ``tip_world_m`` (stand upright)."""
        T = np.eye(4)
        T[:3, 3] = np.asarray(tip_world_m, dtype=float) - self.T_stand_tip[:3, 3]
        return T


def reference_tip_model() -> ReferenceTipModel:
    """The built-in reference tip, read from ``robots/reference_tip/reference_tip.urdf``."""
    path = asset_path(REFERENCE_TIP_URDF)
    return ReferenceTipModel(path, read_only_array(urdf_transform(path, "stand_base", "tip")))
