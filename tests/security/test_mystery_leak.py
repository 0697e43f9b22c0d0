"""What a hostile trainee's own websocket gets in a mystery exercise carries no number of the
true TCP: a raw viser client joins a ``--class --exercise mystery`` server (the class's secret
seed, none given), does what costs a trainee nothing (jogs, the camera buttons, a zero tool typed
in and activated, its spin test far from and at the reference tip, a calibration's Record by
hand, the locked "Hide distance"; switching tabs sends nothing, viser's tabs live in the browser
and every tab's content is sent anyway), keeps every message the server sends it, and decodes
all of it: every number of every message in order, every float array (mesh vertices, points,
poses), every raw byte string read as float32 and float64 (at every alignment), and every
number written in a text (markdown, labels, notifications), and every file sent for download (the
session record, the touches' CSV, the wizard's touches' CSV, a controller file: viser's file transfer parts put together and
read as text). No three consecutive numbers may lie within 0.05 mm of the true TCP read from
the gradebook: in FLANGE (metres and mm, the frame the tool's meshes come in), in WORLD and BASE
at each flange pose the robot took (metres and mm), or as an offset from a zero tool (the
numbers minus the flange position, turned into flange axes; metres and mm). No touch's true
distance is in the exported record or the result (with the poses they give the TCP by
trilateration: ``tests/calibrate/test_exercise_distances.py``).

The clicks reach the session as a browser's do (``guiclick``, with this client's handle); what
is read is only what went over this client's websocket."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial import cKDTree
from tcp_pendant.views.touch_list import TOUCHES_FILENAME
from tcp_pendant.views.wizard_menu import SESSION_FILENAME

from support.app_page import join_as_the_only_trainee
from support.guiclick import choose, click
from support.wsclient import RecordingClient, wait_until

TOKEN = "trainer-token-leak-test-01"
NEAR_M = 5e-5                     # 0.05 mm
NUMBER = re.compile(r"[-−]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")


def _sequences(obj: Any) -> tuple[list[np.ndarray], list[str]]:
    """Every run of numbers in a decoded message (its scalars in order; each float array; each
    byte string as float32 and float64) and every string in it."""
    scalars: list[float] = []
    runs: list[np.ndarray] = []
    texts: list[str] = []

    def walk(o: Any) -> None:
        if isinstance(o, dict):
            for v in o.values():
                walk(v)
        elif isinstance(o, (list, tuple)):
            for v in o:
                walk(v)
        elif isinstance(o, np.ndarray):
            if o.dtype.kind == "f":
                with np.errstate(all="ignore"):
                    runs.append(o.astype(float).ravel())
            elif o.dtype == np.uint8:
                walk(o.tobytes())
        elif isinstance(o, (bytes, bytearray, memoryview)):
            raw = bytes(o)
            for dt in (np.dtype(np.float32), np.dtype(np.float64)):
                for start in range(dt.itemsize):                    # at any alignment
                    n = (len(raw) - start) // dt.itemsize
                    if n >= 3:
                        with np.errstate(all="ignore"):
                            runs.append(np.frombuffer(raw, dtype=dt, count=n, offset=start).astype(float))
        elif isinstance(o, bool):
            return
        elif isinstance(o, (int, float)):
            scalars.append(float(o))
        elif isinstance(o, str):
            texts.append(o)

    walk(obj)
    runs.append(np.array(scalars))
    for t in texts:
        runs.append(np.array([float(x.replace("−", "-")) for x in NUMBER.findall(t)]))
    return runs, texts


def _triples(run: np.ndarray) -> np.ndarray:
    """Every three consecutive numbers of a run (bytes read as floats give NaN, inf and huge
    values: a number beyond 1e6 is no coordinate of a cell a few metres wide, in m or mm)."""
    run = run[np.isfinite(run) & (np.abs(run) < 1e6)] if run.size else run
    if run.size < 3:
        return np.zeros((0, 3))
    return np.lib.stride_tricks.sliding_window_view(run, 3)


def _near(triples: np.ndarray, owner: np.ndarray, targets: list[tuple[str, np.ndarray, float]]
          ) -> list[tuple[str, int]]:
    """(what, message index) of each target some triple lies within the tolerance of (each
    target: name, point, tolerance)."""
    tree = cKDTree(triples)
    hits = []
    for name, point, tol in targets:
        for j in tree.query_ball_point(point, tol)[:3]:
            hits.append((f"{name}: {triples[j].tolist()} vs {point.tolist()}", int(owner[j])))
    return hits


def _downloads(messages: list[dict]) -> dict[str, str]:
    """The files sent to this browser (viser's ``FileTransferStartDownload`` and its
    ``FileTransferPart`` messages, put together in part order), by file name, as UTF-8 text."""
    names = {m["transfer_uuid"]: (m["filename"], m["part_count"])
             for m in messages if m.get("type") == "FileTransferStartDownload"}
    parts: dict[str, dict[int, bytes]] = {}
    for m in messages:
        if m.get("type") == "FileTransferPart" and m.get("transfer_uuid") in names:
            parts.setdefault(m["transfer_uuid"], {})[int(m["part_index"])] = bytes(m["content"])
    out = {}
    for uuid, (name, count) in names.items():
        got = parts.get(uuid, {})
        assert sorted(got) == list(range(count)), f"{name}: parts {sorted(got)} of {count}"
        out[name] = b"".join(got[i] for i in range(count)).decode("utf-8")
    return out


def test_a_hostile_trainee_reads_no_number_of_the_true_tcp(tmp_path: Path, app_factory) -> None:
    app = app_factory(class_db=tmp_path / "class.sqlite3", trainer_token=TOKEN, exercise="mystery")
    assert app.config.exercise_seed is None                       # the class's secret seed
    c = RecordingClient(app.port)
    try:
        s = join_as_the_only_trainee(app, "Mallory")
        assert s.controller.mounted_tool.key.startswith("mystery-") and s.hide_distance

        poses: list[tuple[np.ndarray, np.ndarray]] = []            # (T_world_flange, T_world_base)

        def note_pose() -> None:
            with s.lock:
                poses.append((s.controller.T_world_flange(), s.controller.T_world_base))

        note_pose()
        pendant, tools, cal = s.views["pendant"], s.views["tools"], s.views["calibrate"]
        for ax, sign in (("X", "+"), ("Z", "−"), ("Y", "+"), ("A", "+")):   # jog a little
            choose(pendant.cart_rows[ax], f"{ax} {sign}", s.client)
            note_pose()
        click(pendant.closeup, s.client)
        click(pendant.overview_btn, s.client)
        choose(tools.entry_name, "zero", s.client)                # a zero tool: X = ... = C = 0
        click(tools.entry_save, s.client)
        slot, _ = s.library.find("zero")
        choose(tools.slots, next(o for o in tools.slots.options if o.startswith(f"{slot}")), s.client)
        click(tools.activate, s.client)
        assert s.controller.active_tool is not None and not any(s.controller.active_tool.tcp_mm)
        click(tools.check_active, s.client)                       # far from the tip: refused
        assert "Checking" not in tools.check_md.content
        choose(pendant.hide_distance, False, s.client)            # locked in the exercise
        click(cal.start, s.client)                                # XYZ 4-point
        click(cal.steps.record, s.client)                         # a touch in the air
        with s.lock:                                              # a patient trainee jogs the tip
            ctrl = s.controller                                   # to 2 mm above the spike,
            assert ctrl.jog_cartesian("flange", "A", 10.0).ok      # turned from touch 1
            T = ctrl.T_world_tool_true().copy()
            T[:3, 3] = ctrl.reference_tip_world_m + [0.0, 0.0, 0.002]
            assert ctrl.move_true_tool_to(T).ok
            s.moved()
        note_pose()
        click(tools.check_active, s.client)                       # the spin test at the spike
        note_pose()
        click(cal.steps.next, s.client)
        click(cal.steps.record, s.client)
        note_pose()
        assert "mm" in tools.check_md.content                     # the readings, at the spike
        assert [st.recorded for st in s.workflow.wizard.steps] == [True, True, False, False]
        assert pendant.hide_distance.value and "hidden" in pendant.touch_md.content
        click(s.views["touches"].record, s.client)                # a free touch ("Record point")
        for axis, up_mm in (("A", 200.0), ("B", 0.0)):             # steps 3 and 4 far in the air,
            with s.lock:                                          # the tool turned between them
                assert s.controller.jog_cartesian("world", "Z", up_mm).ok if up_mm else True
                assert s.controller.jog_cartesian("flange", axis, 10.0).ok
                s.moved()
            note_pose()
            click(cal.steps.next, s.client)
            click(cal.steps.record, s.client)
        click(cal.steps.next, s.client)                           # Finish
        assert s.workflow.result is not None, s.workflow.finish_failure
        (row,) = app.gradebook.grades.rows(include_in_progress=True)   # the truth, as the gradebook keeps it
        distances = [t["distance_mm"] for t in app.gradebook.records.touches(row.calibration_id)]
        assert len(distances) == 4 and min(distances) < 3.0 < 150.0 < max(distances)
        assert s.workflow.run.distance_mm == {}                   # nothing of it in the trainee's run
        click(cal.export, s.client)                               # Export session (JSON)
        click(s.views["touches"].export_csv, s.client)            # the free touches as CSV
        assert cal.steps.export.button.visible
        click(cal.steps.export.button, s.client)                  # the wizard's touches as CSV (tcpcal solve)
        click(tools.download, s.client)                           # the active tool's controller file
        marker = "Mallory was here"                               # the last thing sent
        choose(tools.entry_name, marker, s.client)
        wait_until(lambda: any(marker in str(m) for m in list(c.messages)), what="every message sent")

        T_ft = np.array(app.gradebook.records.truth(row.calibration_id)["T_flange_tool_true_m"], dtype=float)
        np.testing.assert_allclose(T_ft, s.controller.mounted_tool.T_flange_tool_true, atol=1e-12)
    finally:
        c.close()

    downloads = _downloads(c.messages)
    assert len(downloads) == 4 and {SESSION_FILENAME, TOUCHES_FILENAME, "xyz4-touches.csv"} <= set(downloads)
    assert downloads["xyz4-touches.csv"].startswith("# tcpcal solve xyz4")       # + the controller file
    record = json.loads(downloads[SESSION_FILENAME])
    assert record["honest"] is True and len(record["wizards"]) == 1
    assert "distance_mm" not in record["wizards"][0], "the export gives the touches' true distances"
    assert "T_flange_tcp_true" not in downloads[SESSION_FILENAME]
    texts = [t for m in c.messages for t in _sequences(m)[1]] + list(downloads.values())
    assert not [t for t in texts if "distance at record" in t or "how far each tip really was" in t]

    tcp = T_ft[:3, 3]
    targets: list[tuple[str, np.ndarray, float]] = [("FLANGE m", tcp, NEAR_M), ("FLANGE mm", tcp * 1e3, NEAR_M * 1e3)]
    for i, (T_wf, T_wb) in enumerate(poses):
        world = T_wf[:3, :3] @ tcp + T_wf[:3, 3]
        base = np.linalg.solve(T_wb, np.append(world, 1.0))[:3]
        targets += [(f"WORLD m @pose {i}", world, NEAR_M), (f"WORLD mm @pose {i}", world * 1e3, NEAR_M * 1e3),
                    (f"BASE m @pose {i}", base, NEAR_M), (f"BASE mm @pose {i}", base * 1e3, NEAR_M * 1e3)]
    assert len(c.messages) > 100 and any(m.get("type") == "MeshMessage" for m in c.messages)
    read = c.messages + [{"type": "download", "name": name, "text": text} for name, text in downloads.items()]
    chunks, owners = [], []
    for k, m in enumerate(read):
        for run in _sequences(m)[0]:
            tri = _triples(run)
            chunks.append(tri)
            owners.append(np.full(len(tri), k))
    triples, owner = np.vstack(chunks), np.concatenate(owners)
    assert len(triples) > 10_000                                      # the meshes were read
    hits = [f"{h} in {read[k].get('type')} {str(read[k].get('name', ''))[:70]}"
            for h, k in _near(triples, owner, targets)]
    for i, (T_wf, _) in enumerate(poses):         # as an offset from a zero tool at each pose
        for scale, tol in ((1.0, NEAR_M), (1e3, NEAR_M * 1e3)):
            off = (triples - T_wf[:3, 3] * scale) @ T_wf[:3, :3]      # FLANGE axes
            hits += [f"offset from the flange at pose {i}: {h} in {read[k].get('type')}"
                     for h, k in _near(off, owner, [(f"FLANGE x{scale:g}", tcp * scale, tol)])]
    assert hits == [], "\n".join(hits[:20])
