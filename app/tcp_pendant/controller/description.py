"""A robot description as a technician brings it: URDF or xacro, ROS packages, meshes.

:func:`load_description` turns the file given with ``--robot`` into one expanded URDF text
that pinocchio (kinematics) and yourdfpy (drawing) read without ROS:

* **xacro** (``.xacro``, ``.urdf.xacro``): expanded with the ``xacro`` package; its
  ``$(find pkg)`` is answered by :class:`PackageFinder`, not by ROS's package index.
* **packages**: ``package://pkg/path`` (and ``$(find pkg)/path`` left in a URDF) name a file
  inside the ROS package ``pkg``. A package is looked for, in this order, in the folders given
  with ``--package-path DIR`` (repeatable), then in the ``ROS_PACKAGE_PATH`` folders (``:``
  separated), each searched like ROS does: the folder itself or any folder below it holding a
  ``package.xml`` whose ``<name>`` is ``pkg`` (or, without a ``package.xml``, a folder named
  ``pkg`` directly inside); then the folders above the description file (a ROS package tree keeps
  its URDF inside its own package, ``pkg/urdf/robot.urdf``).
* **meshes**: every ``<mesh filename>`` of a ``<visual>`` or ``<collision>`` is resolved to an
  absolute file; one that cannot be found is kept as a :class:`MeshRef` with the reason, and
  :meth:`RobotDescription.drawing` says how its link is drawn instead: from its collision
  geometry when all of that is found, else as simple link shapes (``views.meshes``).
* **continuous joints** become revolute joints with limits -360..+360 deg (pinocchio gives an
  unbounded joint two position variables, cos and sin; the pendant jogs angles). A *mimic*
  joint (``<mimic joint="leader" multiplier="m" offset="o"/>``: q = m q_leader + o) is kept as
  it is: pinocchio builds it as a mimic joint with no variable of its own (``kinematics``).

Nothing here imports pinocchio or viser.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import threading
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from tcp_pendant.controller.errors import ControllerError

__all__ = [
    "MeshRef",
    "PackageFinder",
    "RobotDescription",
    "is_xacro",
    "load_description",
    "package_search_path",
]

CONTINUOUS_LIMIT_RAD = 2.0 * math.pi
"""Limits (+-, rad) given to a continuous joint: one full turn either way."""

_PACKAGE_SCAN_DEPTH = 6
"""How deep below a package-path folder a ``package.xml`` is looked for."""

_XACRO_LOCK = threading.Lock()
"""The xacro package keeps its state in module globals: one expansion at a time."""

Drawing = Literal["visual", "collision", "shapes", "none"]


def is_xacro(path: Path) -> bool:
    """True for ``*.xacro`` (including ``*.urdf.xacro``)."""
    return path.name.lower().endswith(".xacro")


def package_search_path(package_paths: Iterable[Path | str] = ()) -> tuple[Path, ...]:
    """The folders searched for ROS packages: ``package_paths`` (``--package-path``) first,
    then ``ROS_PACKAGE_PATH`` (``os.pathsep`` separated; empty entries ignored)."""
    out: list[Path] = [Path(p).expanduser() for p in package_paths]
    for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep):
        if entry.strip():
            out.append(Path(entry.strip()).expanduser())
    seen: set[str] = set()
    unique = []
    for p in out:
        key = str(p.resolve()) if p.exists() else str(p)
        if key not in seen:
            seen.add(key)
            unique.append(p)
    return tuple(unique)


def _package_xml_name(folder: Path) -> str | None:
    """The ``<name>`` of ``folder/package.xml`` (None without a readable one)."""
    try:
        root = ET.parse(folder / "package.xml").getroot()
    except (ET.ParseError, OSError):
        return None
    name = root.findtext("name")
    return name.strip() if name else None


class PackageFinder:
    """Finds ROS packages in the search path and near the description file (module doc).

    Args:
        roots: the search path (:func:`package_search_path`).
        near: the description file; the folders above it are searched last.
    """

    def __init__(self, roots: Sequence[Path], near: Path | None = None) -> None:
        self.roots = tuple(roots)
        self.near = near
        self._index: dict[Path, dict[str, Path]] = {}
        self.found: dict[str, Path | None] = {}

    def _scan(self, root: Path) -> dict[str, Path]:
        if root in self._index:
            return self._index[root]
        index: dict[str, Path] = {}
        if root.is_dir():
            base_depth = len(root.parts)
            for dirpath, dirnames, filenames in os.walk(root):
                here = Path(dirpath)
                if "package.xml" in filenames:
                    name = _package_xml_name(here) or here.name
                    index.setdefault(name, here)
                    dirnames[:] = []             # packages do not nest
                    continue
                if len(here.parts) - base_depth >= _PACKAGE_SCAN_DEPTH:
                    dirnames[:] = []
                dirnames[:] = sorted(d for d in dirnames if not d.startswith("."))
        self._index[root] = index
        return index

    def find(self, package: str) -> Path | None:
        """The folder of ``package``, or None."""
        if package in self.found:
            return self.found[package]
        hit: Path | None = None
        for root in self.roots:
            index = self._scan(root)
            if package in index:
                hit = index[package]
                break
            if (root / package).is_dir():
                hit = root / package
                break
        if hit is None and self.near is not None:
            for folder in self.near.resolve().parents:
                if folder.name == package:
                    hit = folder
                    break
                if (folder / package).is_dir():
                    hit = folder / package
                    break
        self.found[package] = hit
        return hit

    def where(self) -> str:
        """The searched folders in words, for a message."""
        roots = ", ".join(str(r) for r in self.roots) or "none given"
        return f"package path: {roots}; and the folders above {self.near}" if self.near else roots


@dataclass(frozen=True)
class MeshRef:
    """One ``<mesh filename>`` of the description.

    Attributes:
        link: the link that carries it.
        kind: "visual" or "collision".
        uri: the filename as written (``package://...``, relative or absolute).
        path: the resolved file (None: not found).
        reason: why it was not found ("" when found).
    """

    link: str
    kind: Literal["visual", "collision"]
    uri: str
    path: Path | None
    reason: str = ""

    @property
    def found(self) -> bool:
        return self.path is not None


@dataclass(frozen=True, eq=False)
class RobotDescription:
    """An expanded, resolved robot description (module doc). Read-only; shared by sessions.

    Attributes:
        source: the file given (``.urdf`` or ``.xacro``).
        urdf_xml: the expanded URDF text, every found mesh filename absolute, continuous joints
            made revolute with +-360 deg limits.
        links: link names in file order.
        children: child links of each link (the link tree).
        joint_origins: ``{child link: (parent link, xyz origin of the joint, m)}``.
        meshes: every mesh reference, found or not.
        geometry_links: links with a ``<visual>`` (``visual``) or ``<collision>`` (``collision``).
        package_roots: the package search path used.
        continuous_joints: joints that were continuous in the file.
        mimic_joints: ``{joint: (leader, multiplier, offset)}``.
    """

    source: Path
    urdf_xml: str
    links: tuple[str, ...]
    children: Mapping[str, tuple[str, ...]]
    joint_origins: Mapping[str, tuple[str, tuple[float, float, float]]]
    meshes: tuple[MeshRef, ...]
    geometry_links: Mapping[str, frozenset[str]]
    package_roots: tuple[Path, ...] = ()
    continuous_joints: tuple[str, ...] = ()
    mimic_joints: Mapping[str, tuple[str, float, float]] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The file's stem without ``.urdf`` / ``.xacro`` (``kr16_2.urdf.xacro`` -> ``kr16_2``)."""
        name = self.source.name
        for suffix in (".xacro", ".urdf"):
            if name.lower().endswith(suffix):
                name = name[: -len(suffix)]
        return name

    @property
    def missing_meshes(self) -> tuple[MeshRef, ...]:
        """The meshes that were not found (visual and collision)."""
        return tuple(m for m in self.meshes if not m.found)

    def drawing(self, link: str) -> Drawing:
        """How ``link`` is drawn: "visual" (its visual geometry, every mesh of it found),
        "collision" (a visual mesh is missing, its whole collision geometry is found), "shapes"
        (neither: simple link shapes) or "none" (the link has no visual geometry)."""
        if link not in self.geometry_links.get("visual", frozenset()):
            return "none"
        if all(m.found for m in self.meshes if m.link == link and m.kind == "visual"):
            return "visual"
        coll = [m for m in self.meshes if m.link == link and m.kind == "collision"]
        if link in self.geometry_links.get("collision", frozenset()) and all(m.found for m in coll):
            return "collision"
        return "shapes"

    def mesh_warnings(self) -> list[str]:
        """One line per visual mesh that was not found: the mesh, why, what to do, and how its
        link is drawn instead."""
        out = []
        for m in self.meshes:
            if m.found or m.kind != "visual":
                continue
            how = {"collision": "drawn from its collision geometry",
                   "shapes": "drawn as simple link shapes"}.get(self.drawing(m.link), "not drawn")
            out.append(f"robot mesh not found: {m.uri} (link {m.link}): {m.reason}; link {m.link} is {how}.")
        return out


def _resolve_uri(uri: str, base_dir: Path, finder: PackageFinder) -> tuple[Path | None, str]:
    """A mesh filename -> (absolute file or None, reason when None)."""
    text = uri.strip()
    hint = ("give the folder that holds it with --package-path DIR (repeatable) or add it to "
            "ROS_PACKAGE_PATH")
    package: str | None = None
    rest = ""
    if text.startswith("package://"):
        package, _, rest = text[len("package://"):].partition("/")
    elif text.startswith("$(find "):
        inner, close, rest = text[len("$(find "):].partition(")")
        if close:
            package = inner.strip()
            rest = rest.lstrip("/")
    if package is not None:
        folder = finder.find(package)
        if folder is None:
            return None, f"no ROS package {package!r} was found ({finder.where()}): {hint}"
        path = folder / rest
        if path.is_file():
            return path.resolve(), ""
        return None, f"package {package!r} is {folder}, but it has no {rest}: check the package's files"
    if text.startswith("file://"):
        text = text[len("file://"):]
    path = Path(text)
    if not path.is_absolute():
        path = base_dir / path
    if path.is_file():
        return path.resolve(), ""
    return None, (f"no file {path}: put the mesh there, or fix the filename (relative names are "
                  "read from the description's folder)")


@contextlib.contextmanager
def _xacro_find(finder: PackageFinder) -> Iterator[None]:
    """Answer xacro's ``$(find pkg)`` with ``finder`` (xacro asks ROS 2's package index)."""
    from xacro import substitution_args

    def find(pkg: str) -> str:
        folder = finder.find(pkg)
        if folder is None:
            raise ControllerError(f"xacro: $(find {pkg}): no ROS package {pkg!r} was found "
                                  f"({finder.where()}); give the folder that holds it with "
                                  "--package-path DIR or add it to ROS_PACKAGE_PATH.")
        return str(folder)

    saved = substitution_args._eval_find, substitution_args._eval_dict.get("find")
    substitution_args._eval_find = find
    substitution_args._eval_dict["find"] = find
    try:
        yield
    finally:
        substitution_args._eval_find = saved[0]
        substitution_args._eval_dict["find"] = saved[1]


def expand_xacro(path: Path, finder: PackageFinder) -> str:
    """The URDF text of a xacro file (``xacro`` package; ``$(find pkg)`` through ``finder``).

    Raises:
        ControllerError: xacro is not installed, or the file does not expand (xacro's message).
    """
    try:
        import xacro
    except ImportError as exc:  # pragma: no cover - xacro is a runtime dependency
        raise ControllerError("Reading a .xacro robot needs the xacro package: pip install xacro.") from exc
    err = io.StringIO()
    with _XACRO_LOCK, _xacro_find(finder), contextlib.redirect_stderr(err):
        try:
            doc = xacro.process_file(str(path))
            return str(doc.toprettyxml(indent="  "))
        except ControllerError:
            raise
        except Exception as exc:  # xacro raises XacroException, NameError, OSError ...
            detail = " ".join(err.getvalue().split())
            raise ControllerError(f"xacro cannot expand {path}: {exc}"
                                  + (f" ({detail})" if detail else "")) from exc


def _float(text: str | None, default: float) -> float:
    try:
        return float(text) if text is not None else default
    except ValueError:
        return default


def _floats(text: str | None, n: int) -> tuple[float, ...]:
    try:
        vals = tuple(float(v) for v in (text or "").split())
    except ValueError:
        return (0.0,) * n
    return vals if len(vals) == n else (0.0,) * n


def load_description(path: Path | str, package_paths: Iterable[Path | str] = ()) -> RobotDescription:
    """Read, expand and resolve a robot description (module doc).

    Args:
        path: a ``.urdf`` or ``.xacro`` file.
        package_paths: ``--package-path`` folders (searched before ``ROS_PACKAGE_PATH``).

    Raises:
        ControllerError: missing or unreadable file, not a URDF, xacro error.
    """
    source = Path(path).expanduser()
    if not source.is_file():
        raise ControllerError(f"Robot description not found: {source}. Give the path of a .urdf or "
                              ".xacro file.")
    roots = package_search_path(package_paths)
    finder = PackageFinder(roots, near=source)
    root = _robot_element(source, finder)
    links, meshes, geometry_links = _resolve_meshes(root, source.resolve().parent, finder)
    children, origins, continuous, mimic = _read_joints(root, links)
    return RobotDescription(
        source=source.resolve(),
        urdf_xml=ET.tostring(root, encoding="unicode"),
        links=tuple(links),
        children={k: tuple(v) for k, v in children.items()},
        joint_origins=origins,
        meshes=tuple(meshes),
        geometry_links={k: frozenset(v) for k, v in geometry_links.items()},
        package_roots=roots,
        continuous_joints=tuple(continuous),
        mimic_joints=mimic,
    )


def _robot_element(source: Path, finder: PackageFinder) -> ET.Element:
    """The ``<robot>`` element of ``source`` (a URDF, or a xacro expanded).

    Raises:
        ControllerError: unreadable file, not a URDF, xacro error.
    """
    if is_xacro(source):
        text = expand_xacro(source, finder)
    else:
        try:
            text = source.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise ControllerError(f"Cannot read the URDF {source}: {exc}.") from exc
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        raise ControllerError(f"Cannot read the URDF {source}: {exc}.") from exc
    if root.tag != "robot":
        raise ControllerError(f"{source} is not a URDF: its root element is <{root.tag}>, expected <robot>.")
    return root


def _resolve_meshes(root: ET.Element, base_dir: Path,
                    finder: PackageFinder) -> tuple[list[str], list[MeshRef], dict[str, set[str]]]:
    """The links in order, every mesh reference (each ``filename`` found is rewritten in
    ``root`` to its path), and the links with visual / collision geometry."""
    meshes: list[MeshRef] = []
    geometry_links: dict[str, set[str]] = {"visual": set(), "collision": set()}
    links: list[str] = []
    for link in root.findall("link"):
        name = link.get("name", "")
        links.append(name)
        for kind in ("visual", "collision"):
            for element in link.findall(kind):
                geometry_links[kind].add(name)
                for mesh in element.iter("mesh"):
                    uri = mesh.get("filename", "")
                    found, reason = _resolve_uri(uri, base_dir, finder)
                    meshes.append(MeshRef(name, kind, uri, found, reason))
                    if found is not None:
                        mesh.set("filename", str(found))
    return links, meshes, geometry_links


_Origins = dict[str, tuple[str, tuple[float, float, float]]]
"""Child link -> (parent link, the joint's origin xyz in the parent, m)."""
_Mimics = dict[str, tuple[str, float, float]]
"""Mimic joint -> (the joint it follows, multiplier, offset)."""


def _read_joints(root: ET.Element, links: list[str]) -> tuple[dict[str, list[str]], _Origins, list[str], _Mimics]:
    """The joints of ``root``: each link's children, each child's parent and origin, the
    continuous joints (rewritten in ``root`` as revolute within +-``CONTINUOUS_LIMIT_RAD``) and
    the mimic joints."""
    children: dict[str, list[str]] = {name: [] for name in links}
    origins: _Origins = {}
    continuous: list[str] = []
    mimic: _Mimics = {}
    for joint in root.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            continue
        p, c = parent.get("link", ""), child.get("link", "")
        children.setdefault(p, []).append(c)
        origin = joint.find("origin")
        xyz = _floats(origin.get("xyz") if origin is not None else None, 3)
        origins[c] = (p, (xyz[0], xyz[1], xyz[2]))
        jname = joint.get("name", "")
        m = joint.find("mimic")
        if m is not None:
            mimic[jname] = (m.get("joint", ""), _float(m.get("multiplier"), 1.0), _float(m.get("offset"), 0.0))
        if joint.get("type") == "continuous":
            continuous.append(jname)
            joint.set("type", "revolute")
            limit = joint.find("limit")
            if limit is None:
                limit = ET.SubElement(joint, "limit", {"effort": "0", "velocity": "1"})
            limit.set("lower", repr(-CONTINUOUS_LIMIT_RAD))
            limit.set("upper", repr(CONTINUOUS_LIMIT_RAD))
    return children, origins, continuous, mimic
