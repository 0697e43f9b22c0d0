"""Visual meshes of a URDF, loaded once per file and shared by every session (read-only).

yourdfpy loads the URDF with its meshes; each visual geometry is expressed either in the
frame of the link that carries it (robots: the scene moves one frame per link from
pinocchio's ``link_poses``) or in the URDF's root frame (tools and the reference tip: rigid).

A robot is never left undrawn: a link whose visual mesh is missing (or does not load) is drawn
from its collision geometry, or as simple link shapes (a sphere at the link origin and a rod to
each child joint) when that is missing too (``RobotDescription.drawing``); a description with
no geometry at all is drawn as link shapes.
"""

from __future__ import annotations

import contextlib
import io
import threading
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import trimesh
import yourdfpy

from tcp_pendant.controller import ControllerError
from tcp_pendant.controller.description import RobotDescription, load_description

__all__ = ["MeshPart", "link_meshes", "rigid_meshes"]


@dataclass(frozen=True, eq=False)
class MeshPart:
    """One coloured mesh: vertices (V,3) float32 metres, faces (F,3) uint32, rgb 0..255."""

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    rgb: tuple[int, int, int]


@contextlib.contextmanager
def _yourdfpys_deprecated_trimesh_call() -> Iterator[None]:
    """Silence the one DeprecationWarning yourdfpy's mesh loading causes in trimesh (it joins a
    link's several geometries with ``Scene.dump(concatenate=True)``, which trimesh deprecates
    for ``Scene.to_geometry()``; the meshes are the same). Only that message, only here."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=r"`Scene\.dump\(concatenate=True\)` DEPRECATED",
                                category=DeprecationWarning)
        yield


def _load(path: Path) -> yourdfpy.URDF:
    try:
        with _yourdfpys_deprecated_trimesh_call():
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


SHAPE_RGB = (150, 152, 158)
"""Colour of the simple link shapes drawn where no mesh is found."""


def _found_only_xml(description: RobotDescription) -> str:
    """The description's URDF without the <visual>/<collision> elements whose mesh was not found
    (yourdfpy would look for them again and print a line for each)."""
    root = ET.fromstring(description.urdf_xml)
    for link in root.findall("link"):
        for kind in ("visual", "collision"):
            for element in link.findall(kind):
                files = [m.get("filename", "") for m in element.iter("mesh")]
                if any(not (Path(f).is_absolute() and Path(f).is_file()) for f in files):
                    link.remove(element)
    return ET.tostring(root, encoding="unicode")


def _scene_parts(urdf: yourdfpy.URDF, scene: trimesh.Scene | None) -> dict[str, list[MeshPart]]:
    out: dict[str, list[MeshPart]] = {}
    if scene is None:
        return out
    for name, mesh in scene.geometry.items():
        if not isinstance(mesh, trimesh.Trimesh):
            continue
        link = scene.graph.transforms.parents[name]
        T = scene.graph.get(frame_to=name, frame_from=link)[0]
        out.setdefault(link, []).append(_part(name, mesh, T))
    return out


def link_shapes(description: RobotDescription, link: str) -> tuple[MeshPart, ...]:
    """Simple shapes of ``link`` in its own frame: a sphere at its origin and a rod to the origin
    of each child joint; radius 3 % of the description's summed joint offsets (12-50 mm)."""
    total = sum(float(np.linalg.norm(xyz)) for _, xyz in description.joint_origins.values())
    r = min(max(0.03 * total, 0.012), 0.05)
    meshes = [trimesh.creation.icosphere(subdivisions=1, radius=1.2 * r)]
    for child in description.children.get(link, ()):
        xyz = np.asarray(description.joint_origins.get(child, (link, (0.0, 0.0, 0.0)))[1], dtype=float)
        if float(np.linalg.norm(xyz)) > 1e-3:
            meshes.append(trimesh.creation.cylinder(radius=r, segment=np.array([np.zeros(3), xyz]), sections=12))
    out = []
    for i, m in enumerate(meshes):
        v = np.ascontiguousarray(m.vertices, dtype=np.float32)
        f = np.ascontiguousarray(m.faces, dtype=np.uint32)
        v.setflags(write=False)
        f.setflags(write=False)
        out.append(MeshPart(f"{link}_shape_{i}", v, f, SHAPE_RGB))
    return tuple(out)


_LINK_MESHES: dict[tuple[str, str], dict[str, tuple[MeshPart, ...]]] = {}
_LINK_MESHES_LOCK = threading.Lock()


def link_meshes(source: Path | RobotDescription) -> dict[str, tuple[MeshPart, ...]]:
    """Meshes by link name, each in its link's frame (metres): the visual geometry, or what
    stands in for a missing mesh (module doc).

    Kept (the last 16) by the description's resolved URDF text: pendants started one after the
    other on one robot share them; a mesh found since is a new text, so it is loaded.

    Args:
        source: the robot's description (``RobotKinematics.description``), or a URDF file.
    """
    description = source if isinstance(source, RobotDescription) else load_description(Path(source))
    key = (description.urdf_xml, str(description.source.parent))
    with _LINK_MESHES_LOCK:
        hit = _LINK_MESHES.get(key)
    if hit is not None:
        return hit
    out = _link_meshes(description)
    with _LINK_MESHES_LOCK:
        if len(_LINK_MESHES) >= 16:
            _LINK_MESHES.pop(next(iter(_LINK_MESHES)))
        _LINK_MESHES[key] = out
    return out


def _link_meshes(description: RobotDescription) -> dict[str, tuple[MeshPart, ...]]:
    plan = {link: description.drawing(link) for link in description.links}
    need_collision = any(how != "visual" for how in plan.values())
    try:
        with _yourdfpys_deprecated_trimesh_call():
            urdf = yourdfpy.URDF.load(io.StringIO(_found_only_xml(description)), load_meshes=True,
                                      build_collision_scene_graph=need_collision,
                                      load_collision_meshes=need_collision,
                                      mesh_dir=str(description.source.parent))
    except Exception as exc:
        raise ControllerError(f"Cannot load the meshes of {description.source}: {exc}") from exc
    visual = _scene_parts(urdf, urdf.scene)
    collision = _scene_parts(urdf, urdf.collision_scene) if need_collision else {}
    out: dict[str, tuple[MeshPart, ...]] = {}
    for link, how in plan.items():
        if how == "none":
            continue
        if how == "visual" and visual.get(link):
            out[link] = tuple(visual[link])
        elif how in ("visual", "collision") and collision.get(link):   # a visual that did not load
            out[link] = tuple(collision[link])
        else:
            out[link] = link_shapes(description, link)
    if not out:                                  # no geometry at all: every link with a child
        out = {link: link_shapes(description, link) for link in description.links
               if description.children.get(link)}
    return out


@lru_cache(maxsize=16)
def rigid_meshes(urdf_path: Path) -> tuple[MeshPart, ...]:
    """All visual meshes of a rigid URDF (fixed joints at zero) in its root frame (metres)."""
    urdf = _load(Path(urdf_path))
    scene = urdf.scene
    root = scene.graph.base_frame
    return tuple(_part(name, mesh, urdf.get_transform(name, root))
                 for name, mesh in scene.geometry.items() if isinstance(mesh, trimesh.Trimesh))
