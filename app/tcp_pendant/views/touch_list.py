""""Record point" and the list of captured touches, each deletable (viser GUI)."""

from __future__ import annotations

from typing import Any

from tcp_pendant.session import Session, SessionChange

__all__ = ["TouchListView"]


class TouchListView:
    """Builds the touch capture in the current GUI container; rows are rebuilt on change."""

    def __init__(self, session: Session) -> None:
        self.session = session
        gui = session.target.gui
        self.record = gui.add_button("Record point", color="green", icon=None,
                                     hint="Store the current flange pose as a touch.")
        self.folder = gui.add_folder("Touches")
        with self.folder:
            self.empty_md = gui.add_markdown("*No touch recorded.*")
        self._rows: list[Any] = []
        self.record.on_click(session.on_loop(self._on_record))
        session.subscribe(self.on_change)

    def on_change(self, change: SessionChange) -> None:
        """The change signal: redraw the rows when the touches changed; "Record point" is
        hidden while a wizard is open (one Record concept: the wizard dock's Record then)."""
        if change.touches:
            self.rebuild()
        if change.wizard:
            wf = self.session.workflow
            self.record.visible = not (wf is not None and wf.is_open)

    def _on_record(self, _event: Any) -> None:
        t = self.session.record_touch()
        self.session.notify("Point recorded", t.label, kind="success")

    def _delete_cb(self, index: int, label: str) -> Any:
        def cb(_event: Any) -> None:
            # the list may have changed since the button was drawn: delete by label
            labels = [t.label for t in self.session.touches]
            if label in labels:
                self.session.delete_touch(labels.index(label))
        return self.session.on_loop(cb)

    def rebuild(self) -> None:
        """Redraw the rows: one markdown line and one "Delete Pn" button per touch."""
        gui = self.session.target.gui
        for h in self._rows:
            h.remove()
        self._rows = []
        touches = list(self.session.touches)
        self.empty_md.visible = not touches
        with self.folder:
            for i, t in enumerate(touches):
                self._rows.append(gui.add_markdown(f"`{t.label}`"))
                b = gui.add_button(f"Delete P{i + 1}", color="red")
                b.on_click(self._delete_cb(i, t.label))
                self._rows.append(b)
