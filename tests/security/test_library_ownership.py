"""In a class (``--class``) each trainee owns the tool-library slots they saved.

A trainee saves into a free slot or one of their own, renames and deletes only their own, and
holds at most the quota (``--library-quota``, default 3): one trainee cannot fill the library
so that another's Save fails, nor delete or rename a classmate's tool. The trainer (a browser
that opened the trainer view) changes every slot. The owner is kept in the library file, so it
outlives a restart. ``--shared`` and a pendant without a class change any slot, as before.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.classroom.class_room import ClassRoom
from tcp_pendant.classroom.gradebook import Gradebook
from tcp_pendant.controller import builtin_tools
from tcp_pendant.calibrate.pendant_rules import UNRESTRICTED

from tcpcal.library import ToolLibrary, ToolLibraryError
from tcpcal.tool import Tool

from support.calib_helpers import make_session
from support.guiclick import choose, click
from support.wsclient import DrainingClient, wait_until

TOKEN = "trainer-token-of-the-class"


def _tool(name: str, z: float = 100.0) -> Tool:
    return Tool(name=name, tcp_mm=(0.0, 0.0, z))


def _class(tmp_path: Path, quota: int = 3) -> ClassRoom:
    """A classroom on ``tmp_path/class.sqlite3`` (the server's object, without a server)."""
    return ClassRoom(Gradebook(tmp_path / "class.sqlite3"), builtin_tools(), trainer_token=TOKEN,
                     library_quota=quota)


_KEYS: dict[tuple[Path, str], str] = {}   # the browser key each trainee's page keeps


def _trainee(room: ClassRoom, tmp_path: Path, name: str, seed: int = 0):
    """A pendant session on ``tmp_path/tools.json`` whose browser joined the class as ``name``
    (after a restart with the key its page kept)."""
    s = make_session(tmp_path / "tools.json", seed=seed)
    join = room.named(s, name, _KEYS.get((tmp_path, name)))
    if join.new_key is not None:
        _KEYS[(tmp_path, name)] = join.new_key
    return s


def _calibrate_and_save(session, name: str) -> tuple[int, Tool]:
    """The XYZ 4-point by Auto-touch, then "Save to tool library" (slot: the first free one)."""
    session.wizard_commands.start("xyz4")
    while session.workflow.result is None:
        session.wizard_commands.auto_touch(AutoTouchRequest())
    return session.wizard_commands.save_result(name)


def test_one_trainee_cannot_fill_the_library_so_another_trainees_save_still_works(tmp_path: Path) -> None:
    room = _class(tmp_path, quota=3)
    mallory = _trainee(room, tmp_path, "Mallory")
    alice = _trainee(room, tmp_path, "Alice", seed=1)
    for slot in range(1, 17):                                 # the attack: every slot, one by one
        try:
            mallory.tools.store_tool(slot, _tool(f"spam {slot}", slot))
        except ToolLibraryError as exc:
            refusal = str(exc)
            break
    assert slot == 4, "the fourth save must be refused"
    assert refusal.startswith("You have 3 tools in the library (slots 1, 2, 3)")
    assert "delete one of yours first" in refusal
    lib = ToolLibrary(tmp_path / "tools.json")
    assert sorted(lib.tools()) == [1, 2, 3]
    assert lib.owners() == {1: "Mallory", 2: "Mallory", 3: "Mallory"}
    # a calibration (the wizard's Save) and the numeric entry of another trainee still save
    slot, tool = _calibrate_and_save(alice, "Alice pointer")
    assert slot == 4 and lib.get(4) == tool
    alice.tools.store_tool(5, _tool("Alice typed"))
    assert lib.owners() == {1: "Mallory", 2: "Mallory", 3: "Mallory", 4: "Alice", 5: "Alice"}
    # Mallory may still replace a tool of her own (no new slot), and after a delete save again
    mallory.tools.store_tool(2, _tool("spam 2 again"))
    mallory.tools.delete_tool(1)
    mallory.tools.store_tool(6, _tool("spam 6"))
    assert sorted(k for k, v in lib.owners().items() if v == "Mallory") == [2, 3, 6]


def test_a_trainee_cannot_delete_rename_or_overwrite_a_classmates_or_the_trainers_tool(tmp_path: Path) -> None:
    lib = ToolLibrary(tmp_path / "tools.json")
    lib.save(1, _tool("reference pointer"))                  # saved without an owner (before the class)
    room = _class(tmp_path)
    alice = _trainee(room, tmp_path, "Alice")
    mallory = _trainee(room, tmp_path, "Mallory", seed=1)
    alice.tools.store_tool(5, _tool("Alice tool"))
    kept = lib.get(5)
    for attempt in (lambda: mallory.tools.delete_tool(5), lambda: mallory.tools.rename_tool(5, "pwned"),
                    lambda: mallory.tools.store_tool(5, _tool("pwned"))):
        with pytest.raises(ToolLibraryError) as exc:
            attempt()
        assert str(exc.value).startswith("Slot 5 belongs to another trainee:")
        assert "Alice" not in str(exc.value)                   # no classmate's name in the words
        assert "Save into a free slot or one of your own" in str(exc.value)
    assert lib.get(5) == kept and lib.owners()[5] == "Alice"
    # the calibration Save into a chosen slot of another trainee is refused the same way
    mallory.wizard_commands.start("xyz4")
    while mallory.workflow.result is None:
        mallory.wizard_commands.auto_touch(AutoTouchRequest())
    with pytest.raises(ToolLibraryError, match="Slot 5 belongs to another trainee"):
        mallory.wizard_commands.save_result("pwned", 5)
    with pytest.raises(ValueError, match="'Alice tool' is taken by slot 5, a tool that is not yours"):
        mallory.wizard_commands.save_result("Alice tool")                       # no slot chosen: the name's slot
    assert lib.get(5) == kept
    for attempt in (lambda: mallory.tools.delete_tool(1), lambda: mallory.tools.rename_tool(1, "pwned")):
        with pytest.raises(ToolLibraryError, match="Slot 1 is the trainer's"):
            attempt()
    assert lib.get(1) == _tool("reference pointer") and lib.get(5) == kept
    # the owner herself may
    alice.tools.rename_tool(5, "Alice renamed")
    assert lib.get(5).name == "Alice renamed" and lib.owners()[5] == "Alice"
    alice.tools.delete_tool(5)
    assert lib.get(5) is None and lib.owners() == {}
    # a pendant of the class that has not given a name changes nothing
    stranger = make_session(tmp_path / "tools.json", seed=2)
    stranger.tools.set_library_rights(room._library_rights(stranger, None))
    with pytest.raises(ToolLibraryError, match="Join the class with your name first"):
        stranger.tools.store_tool(7, _tool("anonymous"))
    assert lib.get(7) is None


def test_ownership_survives_a_restart_of_the_server(tmp_path: Path) -> None:
    room = _class(tmp_path)
    _trainee(room, tmp_path, "Alice").tools.store_tool(3, _tool("Alice tool"))
    _trainee(room, tmp_path, "Bob", seed=1).tools.store_tool(4, _tool("Bob tool"))
    room.gradebook.close()
    doc = json.loads((tmp_path / "tools.json").read_text(encoding="utf-8"))
    assert doc["owners"] == {"3": "Alice", "4": "Bob"}        # documented in docs/formats.md
    # a new server: a new classroom on the same gradebook, a new library object on the same file
    room2 = _class(tmp_path)
    bob = _trainee(room2, tmp_path, "Bob", seed=2)
    with pytest.raises(ToolLibraryError, match="Slot 3 belongs to another trainee"):
        bob.tools.delete_tool(3)
    bob.tools.rename_tool(4, "Bob tool 2")
    alice = _trainee(room2, tmp_path, "Alice", seed=3)
    alice.tools.delete_tool(3)
    assert ToolLibrary(tmp_path / "tools.json").owners() == {4: "Bob"}
    room2.gradebook.close()


def test_a_library_file_without_owners_loads_and_bad_owner_entries_are_set_aside(tmp_path: Path) -> None:
    path = tmp_path / "tools.json"
    old = {"format": "tcp-pendant-tool-library", "version": 1, "active_slot": None,
           "tools": {"2": _tool("old").to_dict()}}
    path.write_text(json.dumps(old), encoding="utf-8")
    lib = ToolLibrary(path)
    assert lib.owners() == {} and lib.get(2) == _tool("old") and lib.recovery is None
    lib.save(3, _tool("new"))                                 # unrestricted: no owners key written
    assert "owners" not in json.loads(path.read_text(encoding="utf-8"))
    doc = json.loads(path.read_text(encoding="utf-8"))
    doc["owners"] = {"2": "Alice", "9": "Bob", "3": 17}
    path.write_text(json.dumps(doc), encoding="utf-8")
    with pytest.warns(UserWarning):
        assert ToolLibrary(path).owners() == {2: "Alice"}      # slot 9 empty, 17 not a name
    assert sorted(ToolLibrary(path).tools()) == [2, 3]         # every tool kept


def test_without_a_class_and_in_shared_mode_every_slot_is_anyones_as_before(tmp_path: Path) -> None:
    from tcp_pendant.serve.cli import main

    room = _class(tmp_path)
    _trainee(room, tmp_path, "Alice").tools.store_tool(5, _tool("Alice tool"))
    free = make_session(tmp_path / "tools.json", seed=4)     # a pendant without a class (and --shared)
    assert free.tools.library_rights == UNRESTRICTED
    for slot in range(1, 17):
        if slot != 5:
            free.tools.store_tool(slot, _tool(f"tool {slot}"))      # no quota
    free.tools.rename_tool(5, "renamed")
    free.tools.delete_tool(5)
    lib = ToolLibrary(tmp_path / "tools.json")
    assert len(lib.tools()) == 15 and lib.owners() == {}
    assert "owners" not in json.loads((tmp_path / "tools.json").read_text(encoding="utf-8"))
    assert main(["--shared", "--library-quota", "3"]) == 2    # the quota is a class's only
    assert main(["--class", "--library-quota", "0"]) == 2


def test_the_trainer_renames_and_deletes_any_trainees_tool_from_the_tool_tab(app_factory, tmp_path: Path) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN)
    clients = [DrainingClient(app.port), DrainingClient(app.port)]
    try:
        wait_until(lambda: len(app.sessions) == 2 and all("identity" in s.views for s in app.sessions.values()),
                   what="two sessions with their name prompts")
        trainee, trainer = list(app.sessions.values())
        p = trainee.views["identity"]
        choose(p.name_field, "Alice", trainee.client)
        click(p.start, trainee.client)
        trainee.tools.store_tool(4, _tool("Alice tool"))
        panel = trainer.views["tools"]
        wait_until(lambda: 4 in trainer.tools.library_tools, what="the trainer's pendant lists the tool")
        choose(panel.slots, "4: Alice tool", trainer.client)
        click(panel.delete, trainer.client)                   # not the trainer yet: a pendant without a name
        assert app.library.get(4) == _tool("Alice tool")
        q = trainer.views["identity"]
        choose(q.token_field, TOKEN, trainer.client)
        click(q.open_trainer, trainer.client)
        assert "trainer" in trainer.views
        panel = trainer.views["tools"]                        # the dashboard's own tool library folder
        choose(panel.slots, "4: Alice tool", trainer.client)
        assert "Saved by trainee Alice." in panel.slot_md.content
        choose(panel.new_name, "checked by the trainer", trainer.client)
        click(panel.rename, trainer.client)
        assert app.library.get(4).name == "checked by the trainer" and app.library.owners() == {4: "Alice"}
        tpanel = trainee.views["tools"]
        wait_until(lambda: "Yours" in tpanel.slot_md.content, what="the trainee's pendant says the slot is hers")
        click(panel.delete, trainer.client)
        assert app.library.get(4) is None and app.library.owners() == {}
    finally:
        for c in clients:
            c.close()
