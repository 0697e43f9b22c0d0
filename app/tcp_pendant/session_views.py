"""The views a session shows, by name, and the scene labels two of them share.

The server's view builders put each view of a session in its :class:`ViewRegistry`
(``session.views["pendant"]``, ...) so tests can reach it; app code never looks a view up
through it (views render the session's state and never call each other). What views share is
:class:`SceneLabels`: the robot scene draws the labels at the tool and the tip, the wizards'
scene moves them apart and adds its own, and presenter mode draws them all larger.
"""

from __future__ import annotations

from collections.abc import Iterator, MutableMapping
from dataclasses import dataclass, fields
from typing import Protocol

import numpy as np
import numpy.typing as npt

__all__ = ["SceneLabel", "SceneLabels", "ViewRegistry"]


class SceneLabel(Protocol):
    """What views do with a label of the 3D scene (a ``viser.LabelHandle``; the session's layer
    imports no viser): its text, its place (``position``: in its parent frame, metres) and its
    font's scale."""

    text: str
    font_screen_scale: float

    @property
    def position(self) -> npt.NDArray[np.float64]: ...

    @position.setter
    def position(self, position: tuple[float, float, float] | np.ndarray) -> None: ...


@dataclass
class SceneLabels:
    """The labels of a session's 3D scene that more than one view touches (None: not drawn).

    Attributes:
        world: the WORLD frame's label (the robot scene).
        flange: at the flange (the robot scene; the wizards' scene places it apart).
        tool: at the active TOOL frame (likewise).
        tip: at the reference tip (likewise).
        computed: at the computed TOOL frame of a result (the wizards' scene).
        true: at the true TOOL frame of a result (the wizards' scene, training).
        target: at an ABC wizard's target orientation (the wizards' scene).
    """

    world: SceneLabel | None = None
    flange: SceneLabel | None = None
    tool: SceneLabel | None = None
    tip: SceneLabel | None = None
    computed: SceneLabel | None = None
    true: SceneLabel | None = None
    target: SceneLabel | None = None

    def drawn(self) -> dict[str, SceneLabel]:
        """The labels drawn, by field name (presenter mode restyles them all)."""
        out: dict[str, SceneLabel] = {}
        for f in fields(self):
            label = getattr(self, f.name)
            if label is not None:
                out[f.name] = label
        return out

    def clear(self) -> None:
        """Forget every label (the views that drew them are gone)."""
        for f in fields(self):
            setattr(self, f.name, None)


class ViewRegistry(MutableMapping[str, object]):
    """A session's views by name (``"scene"``, ``"pendant"``, ``"tools"``, ...), for tests, and
    the :class:`SceneLabels` its views share (:attr:`labels`)."""

    def __init__(self) -> None:
        self._views: dict[str, object] = {}
        self.labels = SceneLabels()

    def __getitem__(self, name: str) -> object:
        return self._views[name]

    def __setitem__(self, name: str, view: object) -> None:
        self._views[name] = view

    def __delitem__(self, name: str) -> None:
        del self._views[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._views)

    def __len__(self) -> int:
        return len(self._views)

    def drop(self) -> None:
        """Forget every view and every shared label (the session's views were taken down)."""
        self._views.clear()
        self.labels.clear()
