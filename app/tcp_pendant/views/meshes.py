"""Visual meshes of a URDF, loaded once per file and shared by every session (read-only).

yourdfpy loads the URDF with its meshes; each visual geometry is expressed either in the
frame of the link that carries it (robots: the scene moves one frame per link from
pinocchio's ``link_poses``) or in the URDF's root frame (tools and the reference tip: rigid).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import trimesh
import yourdfpy

from tcp_pendant.controller import ControllerError

__all__ = ["MeshPart", "link_meshes", "rigid_meshes"]


@dataclass(frozen=True, eq=False)
class MeshPart:
    """One coloured mesh: vertices (V,3) float32 metres, faces (F,3) uint32, rgb 0..255."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    rgb: tuple[int, int, int]


def _load(path: Path) -> yourdfpy.URDF:
    try:
        return yourdfpy.URDF.load(str(path), load_meshes=True, build_collision_scene_graph=False,
                                  load_collision_meshes=False)
    except Exception as exc:
        raise ControllerError(f"Cannot load the visual meshes of {path}: {exc}") from exc


def _part(name: str, mesh: trimesh.Trimesh, T: np.ndarray) -> MeshPart:
    m = mesh.copy()
    m.apply_transform(T)
    rgb = (170, 174, 180)
    try:
        if isinstance(m.visual, trimesh.visual.ColorVisuals):   # a texture keeps the grey
            color = np.asarray(m.visual.main_color)[:3]
            rgb = (int(color[0]), int(color[1]), int(color[2]))
    except Exception:
        pass
    v = np.ascontiguousarray(m.vertices, dtype=np.float32)
    f = np.ascontiguousarray(m.faces, dtype=np.uint32)
    v.setflags(write=False)
    f.setflags(write=False)
    return MeshPart(name, v, f, rgb)


@lru_cache(maxsize=16)
def link_meshes(urdf_path: Path) -> dict[str, tuple[MeshPart, ...]]:
    """Visual meshes by link name, each in its link's frame (metres)."""
    urdf = _load(Path(urdf_path))
    scene = urdf.scene
    out: dict[str, list[MeshPart]] = {}
    for name, mesh in scene.geometry.items():
        if not isinstance(mesh, trimesh.Trimesh):
            continue
        link = scene.graph.transforms.parents[name]
        out.setdefault(link, []).append(_part(name, mesh, urdf.get_transform(name, link)))
    return {k: tuple(v) for k, v in out.items()}


@lru_cache(maxsize=16)
def rigid_meshes(urdf_path: Path) -> tuple[MeshPart, ...]:
    """All visual meshes of a rigid URDF (fixed joints at zero) in its root frame (metres)."""
    urdf = _load(Path(urdf_path))
    scene = urdf.scene
    root = scene.graph.base_frame
    return tuple(_part(name, mesh, urdf.get_transform(name, root))
                 for name, mesh in scene.geometry.items() if isinstance(mesh, trimesh.Trimesh))
