"""Where the robot, tool and reference-tip URDFs live.

The URDFs we author are in the repository's ``robots/`` folder. A wheel install maps that
folder into the package as ``tcp_pendant/_robots`` (``pyproject.toml``,
``[tool.hatch.build.targets.wheel.force-include]``); an editable install reads ``robots/``
from the source tree. :func:`robots_dir` picks whichever exists, packaged copy first.

The ``example-robot-data`` package (a test dependency) ships URDFs such as the UR5 as data
files under ``cmeel.prefix/share/example-robot-data/robots``; :func:`example_robot_urdf`
finds them through the package's installed-file list.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

import tcp_pendant
from tcp_pendant.controller.errors import ControllerError

__all__ = [
    "ROBOT_URDFS",
    "TOOL_URDFS",
    "REFERENCE_TIP_URDF",
    "robots_dir",
    "asset_path",
    "example_robot_data_dir",
    "example_robot_urdf",
]

ROBOT_URDFS: dict[str, str] = {
    "kr6": "kr6_r900/kr6_r900.urdf",
    "gp12": "gp12/gp12.urdf",
}
"""Built-in robots: key -> URDF path relative to :func:`robots_dir`."""

TOOL_URDFS: dict[str, str] = {
    "pointer": "tools/pointer.urdf",
    "torch": "tools/torch.urdf",
    "gripper": "tools/gripper.urdf",
}
"""Built-in tools: key -> URDF path relative to :func:`robots_dir`."""

REFERENCE_TIP_URDF = "reference_tip/reference_tip.urdf"
"""The reference tip (spike on a stand), relative to :func:`robots_dir`."""


def robots_dir() -> Path:
    """The folder holding the authored URDFs.

    Returns ``<tcp_pendant package>/_robots`` when it exists (wheel install), else the
    repository's ``robots/`` folder (editable install: ``app/tcp_pendant/../../robots``).
    """
    packaged = Path(tcp_pendant.__file__).resolve().parent / "_robots"
    if packaged.is_dir():
        return packaged
    return Path(tcp_pendant.__file__).resolve().parents[2] / "robots"


def asset_path(relative: str) -> Path:
    """``robots_dir() / relative``, checked to exist.

    Raises:
        ControllerError: the file is missing (names the path and the folder searched).
    """
    path = robots_dir() / relative
    if not path.is_file():
        raise ControllerError(
            f"Robot asset {relative!r} not found in {robots_dir()}: the robots/ folder is "
            "incomplete; reinstall tcp-pendant or check out the full repository."
        )
    return path


def example_robot_data_dir() -> Path | None:
    """The ``robots`` folder of the installed ``example-robot-data`` package, or None.

    Looked up through the distribution's installed-file list (the package has no importable
    Python module in its cmeel build), then through ``example_robot_data.getModelPath`` if a
    module exists.
    """
    try:
        dist = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        dist = None
    if dist is not None:
        for f in dist.files or ():
            parts = Path(str(f)).parts
            if "example-robot-data" in parts and parts[-1].endswith(".urdf"):
                idx = parts.index("example-robot-data")
                candidate = Path(str(dist.locate_file(Path(*parts[: idx + 1])))) / "robots"
                if candidate.is_dir():
                    return candidate
    try:  # pragma: no cover - only with the pip build of example-robot-data
        import example_robot_data

        return Path(example_robot_data.getModelPath("ur_description/urdf/ur5_robot.urdf")) / "robots"
    except Exception:
        return None


def example_robot_urdf(relative: str = "ur_description/urdf/ur5_robot.urdf") -> Path:
    """A URDF shipped by ``example-robot-data`` (default: the UR5).

    Raises:
        ControllerError: the package is not installed or has no such file.
    """
    root = example_robot_data_dir()
    if root is None:
        raise ControllerError(
            "The example-robot-data package is not installed: `pip install example-robot-data` "
            "(it is in the test extra: `pip install tcp-pendant[test]`)."
        )
    path = root / relative
    if not path.is_file():
        raise ControllerError(f"example-robot-data has no {relative!r} (looked in {root}).")
    return path
