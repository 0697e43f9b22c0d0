""""The math" view: every method's equations filled in with the run's numbers.

Each test drives a wizard through the session's commands on an in-process pendant (the
``page`` fixture: the Calibrate tab with its views), then checks
* that the folder is shown with the blocks of the method;
* the structured numbers of each block against an independent numpy recomputation from the
  recorded touches (``T_world_flange_m`` of ``wizard.recorded_poses``, metres -> mm);
* the displayed text: every decimal number of a block's monospace lines, parsed back from the
  markdown the browser gets, is that block's number at its shown precision.
"""

from __future__ import annotations

import html
import math
import re

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from tcp_pendant.calibrate import AutoTouchRequest
from tcp_pendant.calibrate.math_view import MAX_LINE, MAX_WIDE_LINE, MathSheet, math_sheet
from tcp_pendant.text_escape import escape_markdown

from support.calib_helpers import library_tool_with_true_tcp, true_frame
from tcpcal.tool import Tool
from support.calib_page import Page

pytestmark = pytest.mark.app_page(cls=Page, seed=5)

P_PARALLEL = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])   # (PA-1)
_BLOCK = re.compile(r'<div class="math-block" data-key="([^"]+)"[^>]*>(.*?)</div>', re.S)
_NUMBER = re.compile(r"-?\d+\.\d+")


# ------------------------------------------------------------------ helpers
def shown_blocks(md: str) -> dict[str, list[str]]:
    """The monospace lines of every block in the markdown, by data-key, as the browser reads them."""
    return {key: html.unescape(body.replace("&nbsp;", " ")).split("<br>") for key, body in _BLOCK.findall(md)}


def assert_text_is_the_numbers(md: str, sheet: MathSheet) -> None:
    """Every block's decimal numbers in the text are its values, in order, at their precision;
    and the markdown holds no other decimal number (intro, labels and notes have none)."""
    blocks = shown_blocks(md)
    assert list(blocks) == [b.key for b in sheet.blocks]
    too_long = [line for key, lines in blocks.items() for line in lines
                if len(line) > (MAX_WIDE_LINE if key == "A" else MAX_LINE)]
    assert not too_long, too_long                                   # fits the presenter panel
    for b in sheet.blocks:
        got = [float(x) for line in blocks[b.key] for x in _NUMBER.findall(line)]
        want = [(x, s.decimals) for s in b.values.values() for x in s.flat()]
        assert len(got) == len(want), (b.key, got, want)
        for g, (w, d) in zip(got, want):
            assert abs(g - w) <= 0.5001 * 10.0 ** -d, (b.key, g, w)
    outside = _BLOCK.sub("", md)
    assert not _NUMBER.findall(outside.replace("\\.", ".")), "a decimal number outside the blocks"


def value(sheet: MathSheet, key: str, name: str) -> np.ndarray:
    return sheet.block(key).values[name].value


def touches_mm(wiz, steps=None) -> tuple[np.ndarray, np.ndarray]:
    """R (N,3,3) and f (N,3) mm of the recorded poses, straight from the wizard's record."""
    poses = wiz.recorded_poses
    steps = sorted(poses) if steps is None else steps
    T = np.array([poses[i].T_world_flange_m for i in steps])
    return T[:, :3, :3], T[:, :3, 3] * 1000.0


def check_design(sheet: MathSheet, md: str, R: np.ndarray) -> None:
    """(4P-3)'s A = [R_i -I] stacked (3N x 6), built here with numpy: its R part as shown, its
    singular values and rank, and each shown row's -I part."""
    A = np.vstack([np.hstack([Ri, -np.eye(3)]) for Ri in R])
    assert A.shape == (3 * len(R), 6)
    np.testing.assert_allclose(value(sheet, "A", "A_R"), A[:, :3], atol=1e-12)
    s = np.linalg.svd(A, compute_uv=False)
    np.testing.assert_allclose(value(sheet, "A", "sigma"), s, atol=1e-9)
    rank = int(np.sum(s > 1e-6 * s[0]))
    lines = shown_blocks(md)["A"]
    assert f"rank {rank} of 6" in lines
    rows = lines[1:1 + 3 * len(R)]
    assert [row.split()[3:] for row in rows] == [[str(int(x)) for x in A[k, 3:]] for k in range(len(rows))]
    assert len(rows) == 3 * len(R)


def lstsq_4p3(R: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(4P-3) by hand: [R_i -I] (t, r) = -f_i, stacked 3N x 6, numpy lstsq."""
    A = np.vstack([np.hstack([Ri, -np.eye(3)]) for Ri in R])
    x, *_ = np.linalg.lstsq(A, -f.reshape(-1), rcond=None)
    return x[:3], x[3:]


def math_md(v) -> str:
    assert v.math.folder.visible
    return v.math.md.content


def touch(s, n: int = 1, sigma_mm: float = 0.3) -> None:
    for _ in range(n):
        with s.lock:
            assert s.wizard_commands.auto_touch(AutoTouchRequest(sigma_mm=sigma_mm)).ok


def check_pair(sheet: MathSheet, R: np.ndarray, f: np.ndarray, a: int, b: int) -> None:
    """Lecture Eq. (7) for touches a, b (0-based in R, f): the matrix, the right side, the
    singular values (one zero: rank 2) and u the axis the tool turned about between them."""
    D = R[a] - R[b]
    np.testing.assert_allclose(value(sheet, "pair", "R_a-R_b"), D, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "pair", "-(f_a-f_b)"), -(f[a] - f[b]), atol=1e-9)
    s = np.linalg.svd(D, compute_uv=False)
    np.testing.assert_allclose(value(sheet, "pair", "sigma"), s, atol=1e-9)
    assert s[2] < 1e-9 * s[0]
    u = value(sheet, "pair", "u")
    axis = Rotation.from_matrix(R[b].T @ R[a]).as_rotvec()
    assert abs(float(u @ axis)) / np.linalg.norm(axis) == pytest.approx(1.0, abs=1e-9)
    assert np.linalg.norm(D @ u) < 1e-9


# ------------------------------------------------------------------ XYZ 4-point
def test_xyz4_math_is_live_from_the_first_touch_and_matches_numpy(page) -> None:
    p = page()
    v, s = p.view, p.session
    assert not v.math.folder.visible
    with s.lock:
        s.wizard_commands.start("xyz4")
    wiz = s.workflow.wizard
    assert v.math.folder.visible and v.math.sheet is not None and v.math.sheet.blocks == ()
    touch(s)
    sheet = v.math.sheet
    R, f = touches_mm(wiz)
    assert [b.key for b in sheet.blocks] == ["touch-1", "A"]
    np.testing.assert_allclose(value(sheet, "touch-1", "R_1"), R[0], atol=1e-12)
    np.testing.assert_allclose(value(sheet, "touch-1", "f_1"), f[0], atol=1e-9)
    assert sheet.intro.startswith("1 touch recorded.")
    check_design(sheet, math_md(v), R)
    assert "rank 3 of 6" in shown_blocks(math_md(v))["A"]
    assert_text_is_the_numbers(math_md(v), sheet)

    touch(s)                                            # two touches: rank 2, no solution
    sheet, md = v.math.sheet, math_md(v)
    R, f = touches_mm(wiz)
    assert [b.key for b in sheet.blocks] == ["touch-1", "touch-2", "A", "pair", "stack"]
    assert sheet.intro.startswith("2 touches recorded.")
    check_design(sheet, md, R)
    assert "rank 5 of 6" in shown_blocks(md)["A"]                # t along the turning axis is free
    check_pair(sheet, R, f, 0, 1)
    assert "rank 2 of 3" in shown_blocks(md)["pair"] and "rank 2 of 3" in shown_blocks(md)["stack"]
    assert "normally a singular matrix and results in no solution" in md
    assert "the TCP along u cannot be determined" in md
    assert_text_is_the_numbers(md, sheet)

    touch(s, 2)                                         # four touches: the result
    res = s.workflow.result
    assert res is not None and v.result.folder.visible and v.math.folder.visible
    sheet, md = v.math.sheet, math_md(v)
    R, f = touches_mm(wiz)
    assert [b.key for b in sheet.blocks] == ["touch-1", "touch-2", "touch-3", "touch-4", "A", "pair", "stack",
                                             "lstsq", "sphere"]
    check_design(sheet, md, R)
    assert "rank 6 of 6" in shown_blocks(md)["A"]
    check_pair(sheet, R, f, 2, 3)                       # the last two touches by default
    # the stack of consecutive pairs: rank 3, its singular values, Eq. (8) by numpy's lstsq
    D = np.vstack([R[k] - R[k + 1] for k in range(3)])
    y = np.concatenate([-(f[k] - f[k + 1]) for k in range(3)])
    np.testing.assert_allclose(value(sheet, "stack", "sigma"), np.linalg.svd(D, compute_uv=False), atol=1e-9)
    assert "rank 3 of 3" in shown_blocks(md)["stack"]
    t_pinv, *_ = np.linalg.lstsq(D, y, rcond=None)
    np.testing.assert_allclose(value(sheet, "stack", "t_pinv"), t_pinv, atol=1e-9)
    np.testing.assert_allclose(t_pinv, res.estimators["pairwise"].tcp, atol=1e-9)     # tcpcal's pairwise
    # (4P-3): the solver's number, and numpy's
    t, r = lstsq_4p3(R, f)
    np.testing.assert_allclose(value(sheet, "lstsq", "t_pinv"), t_pinv, atol=1e-9)        # side by side
    np.testing.assert_allclose(value(sheet, "lstsq", "t_lstsq"), res.tcp_mm, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "lstsq", "t_lstsq"), t, atol=1e-8)
    np.testing.assert_allclose(value(sheet, "lstsq", "r_lstsq"), r, atol=1e-8)
    assert float(value(sheet, "lstsq", "ci95")) == pytest.approx(res.ci95_mm)
    assert float(value(sheet, "lstsq", "diff")) == pytest.approx(np.linalg.norm(t - t_pinv), abs=1e-8)
    assert escape_markdown("maximum-likelihood") in md and "discards information" in md
    # (4P-1a): |f_i|^2 = 2 f_i . r + k (not centred), radius^2 = k + |r|^2
    H = np.column_stack([2.0 * f, np.ones(4)])
    z, *_ = np.linalg.lstsq(H, (f * f).sum(axis=1), rcond=None)
    centre = z[:3]
    np.testing.assert_allclose(value(sheet, "sphere", "centre"), centre, atol=1e-6)
    radius = math.sqrt(z[3] + centre @ centre)
    assert float(value(sheet, "sphere", "radius")) == pytest.approx(radius, abs=1e-6)
    assert np.linalg.norm(f - centre, axis=1) == pytest.approx([radius] * 4, abs=1e-6)   # 4 points: exact
    t_sphere = np.mean([Ri.T @ (centre - fi) for Ri, fi in zip(R, f)], axis=0)
    np.testing.assert_allclose(value(sheet, "sphere", "t_sphere"), t_sphere, atol=1e-6)
    np.testing.assert_allclose(t_sphere, res.estimators["sphere"].tcp, atol=1e-6)
    assert_text_is_the_numbers(md, sheet)

    # a chosen pair
    assert v.math.pair.visible and "1 and 3" in v.math.pair.options
    p.choose(v.math.pair, "1 and 3")
    check_pair(v.math.sheet, R, f, 0, 2)
    assert "touches 1 and 3" in math_md(v)

    # jogging does not recompute the sheet; a wizard change does
    n = v.math.renders
    with s.lock:
        s.controller.jog_joint(0, 3.0)
        s.moved()
        s.controller.jog_joint(1, -2.0)
        s.moved()
    assert v.math.renders == n
    with s.lock:
        s.wizard_commands.back()
    assert v.math.renders == n + 1

    # an exercise: the same sheet, the trainee's data only (no number other than the blocks')
    before = math_md(v)
    with s.lock:
        s.wizard_commands.set_hide_truth(True)
    assert math_md(v) == before
    assert_text_is_the_numbers(math_md(v), v.math.sheet)


def test_dropped_touches_leave_the_math_as_they_leave_the_solver(page) -> None:
    p = page()
    v, s = p.view, p.session
    with s.lock:
        s.wizard_commands.start("xyz4", n_points=5)
    touch(s, 5)
    with s.lock:
        s.wizard_commands.edit_result(lambda w: w.set_excluded([1]))
    res = s.workflow.result
    sheet = v.math.sheet
    assert [b.key for b in sheet.blocks][:4] == ["touch-1", "touch-3", "touch-4", "touch-5"]
    R, f = touches_mm(s.workflow.wizard, [0, 2, 3, 4])
    np.testing.assert_allclose(value(sheet, "lstsq", "t_lstsq"), res.tcp_mm, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "lstsq", "t_lstsq"), lstsq_4p3(R, f)[0], atol=1e-8)
    assert "(1,3), (3,4), (4,5)" in sheet.block("stack").title


# ------------------------------------------------------------------ XYZ reference
def test_reference_math_r_then_t2_in_world_and_in_flange(page) -> None:
    p = page()
    v, s = p.view, p.session
    ref = library_tool_with_true_tcp("pointer", "Pointer")
    s.library.save(1, ref)
    with s.lock:
        s.wizard_commands.start("reference", slot=1, reference_tool_key="pointer", new_tool_key="torch")
    touch(s)
    sheet = v.math.sheet
    assert [b.key for b in sheet.blocks] == ["reference-point"]
    with s.lock:
        s.wizard_commands.mount_required_tool()
    touch(s)
    res = s.workflow.result
    assert res is not None
    sheet, md = v.math.sheet, math_md(v)
    R, f = touches_mm(s.workflow.wizard)
    t1 = np.asarray(ref.tcp_mm)
    r = f[0] + R[0] @ t1
    np.testing.assert_allclose(value(sheet, "reference-point", "t_1"), t1, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "reference-point", "r"), r, atol=1e-9)
    np.testing.assert_allclose(value(sheet, "new-tcp", "t_2_world"), r - f[1], atol=1e-9)
    np.testing.assert_allclose(value(sheet, "new-tcp", "t_2"), R[1].T @ (r - f[1]), atol=1e-9)
    np.testing.assert_allclose(value(sheet, "new-tcp", "t_2"), res.tcp_mm, atol=1e-9)        # the solver's
    assert "r = f₁ + R₁ t₁" in shown_blocks(md)["reference-point"]
    assert escape_markdown("(REF-1)") in md
    assert_text_is_the_numbers(md, sheet)


# ------------------------------------------------------------------ three-point
def _three_point_common(sheet: MathSheet, R: np.ndarray, f: np.ndarray, t: np.ndarray) -> np.ndarray:
    r = R[0] @ t + f[0]                                            # (7)
    np.testing.assert_allclose(value(sheet, "eq7", "r"), r, atol=1e-9)
    v1 = R[1].T @ (r - f[1])                                       # (8)-(17)
    delta1 = -np.linalg.norm(v1 - t)
    np.testing.assert_allclose(value(sheet, "eq8-17", "V1"), v1, atol=1e-9)
    assert float(value(sheet, "eq8-17", "delta1")) == pytest.approx(delta1, abs=1e-9) and delta1 < -20.0
    c1 = (v1 - t) / delta1
    np.testing.assert_allclose(value(sheet, "eq8-17", "c1"), c1, atol=1e-12)
    return r


def test_three_point_variants_1_and_2_follow_the_papers_steps(page) -> None:
    p = page(tool="torch")
    v, s = p.view, p.session
    tool = library_tool_with_true_tcp("torch", "Torch")
    s.library.save(1, tool)
    t = np.asarray(tool.tcp_mm)
    with s.lock:
        s.wizard_commands.start("three-point", slot=1)
    touch(s, 2)
    sheet = v.math.sheet
    assert [b.key for b in sheet.blocks] == ["eq7", "eq8-17"]            # live, as the poses arrive
    touch(s)
    res = s.workflow.result
    assert res is not None
    sheet, md = v.math.sheet, math_md(v)
    assert [b.key for b in sheet.blocks] == ["eq7", "eq8-17", "eq18-24", "eq30"]
    R, f = touches_mm(s.workflow.wizard)
    r = _three_point_common(sheet, R, f, t)
    c1 = value(sheet, "eq8-17", "c1")
    v2 = R[2].T @ (r - f[2])                                       # (18)-(24)
    np.testing.assert_allclose(value(sheet, "eq18-24", "V2"), v2, atol=1e-9)
    c2 = (v2 - t) / np.linalg.norm(v2 - t)
    np.testing.assert_allclose(value(sheet, "eq18-24", "c2"), c2, atol=1e-12)
    assert float(value(sheet, "eq18-24", "c1.c2")) == pytest.approx(c1 @ c2, abs=1e-12)
    defect = abs(90.0 - math.degrees(math.acos(float(c1 @ c2))))
    assert float(value(sheet, "eq18-24", "defect")) == pytest.approx(defect, abs=1e-9)
    assert float(value(sheet, "eq30", "defect_tcpcal")) == pytest.approx(res.orthogonality_defect_deg, abs=1e-12)
    assert defect == pytest.approx(res.orthogonality_defect_deg, abs=1e-9) and defect > 0.0   # noisy touches
    c2o = c2 - (c1 @ c2) * c1
    c2o /= np.linalg.norm(c2o)
    np.testing.assert_allclose(value(sheet, "eq18-24", "c2_straight"), c2o, atol=1e-12)    # printed
    np.testing.assert_allclose(value(sheet, "eq30", "R_n,n*")[:, 1], c2o, atol=1e-12)     # = the middle column
    c3 = np.cross(c1, c2o)                                         # (30)
    np.testing.assert_allclose(value(sheet, "eq30", "c3"), c3, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "eq30", "R_n,n*"), res.rotation, atol=1e-12)   # the solver's
    assert "c1 = (c11, c21, c31)" in shown_blocks(md)["eq8-17"]
    assert_text_is_the_numbers(md, sheet)

    with s.lock:                                                   # variant 2: V(3), Δ3, Δ4
        s.wizard_commands.set_variant(2)
    touch(s)
    res = s.workflow.result
    assert res is not None and res.method == "three-point-2"
    sheet, md = v.math.sheet, math_md(v)
    assert [b.key for b in sheet.blocks] == ["eq7", "eq8-17", "eq25-29", "eq30"]
    R, f = touches_mm(s.workflow.wizard)
    r = _three_point_common(sheet, R, f, t)
    c1 = value(sheet, "eq8-17", "c1")
    w = R[2].T @ (r - f[2]) - t
    delta3 = c1 @ w
    delta4 = np.linalg.norm(w - delta3 * c1)
    assert float(value(sheet, "eq25-29", "delta3")) == pytest.approx(delta3, abs=1e-9)
    assert float(value(sheet, "eq25-29", "delta4")) == pytest.approx(delta4, abs=1e-9)
    c2 = (w - delta3 * c1) / delta4
    np.testing.assert_allclose(value(sheet, "eq25-29", "c2"), c2, atol=1e-12)
    assert abs(float(value(sheet, "eq25-29", "c1.c2"))) < 1e-12
    np.testing.assert_allclose(value(sheet, "eq30", "c3"), np.cross(c1, c2), atol=1e-12)
    np.testing.assert_allclose(value(sheet, "eq30", "R_n,n*"), res.rotation, atol=1e-12)
    assert float(value(sheet, "eq30", "defect_tcpcal")) == 0.0
    assert_text_is_the_numbers(md, sheet)


# ------------------------------------------------------------------ ABC world
def test_abc_world_math_is_the_flange_rotation_transposed_times_the_target(page) -> None:
    p = page(tool="torch")
    v, s = p.view, p.session
    s.library.save(1, library_tool_with_true_tcp("torch", "Torch"))
    with s.lock:
        s.wizard_commands.start("abc-world", slot=1)
    assert v.math.folder.visible and v.math.sheet.blocks == ()
    touch(s, sigma_mm=0.0)
    res = s.workflow.result
    sheet, md = v.math.sheet, math_md(v)
    R, _ = touches_mm(s.workflow.wizard)
    np.testing.assert_allclose(value(sheet, "pa", "R_0,n"), R[0], atol=1e-12)
    np.testing.assert_allclose(value(sheet, "pa", "R_0,n*"), P_PARALLEL, atol=0)
    np.testing.assert_allclose(value(sheet, "pa", "R_n,n*"), R[0].T @ P_PARALLEL, atol=1e-12)
    np.testing.assert_allclose(value(sheet, "pa", "R_n,n*"), res.rotation, atol=1e-12)      # the solver's
    np.testing.assert_allclose(value(sheet, "pa", "abc"), res.abc_deg, atol=1e-9)
    assert escape_markdown("(PA-1), (PA-2)") in md
    assert_text_is_the_numbers(md, sheet)


# ------------------------------------------------------------------ TCP & Z, X
def test_tcp_zx_math_touches_then_the_z_and_x_directions(page) -> None:
    p = page()
    v, s = p.view, p.session
    with s.lock:
        s.wizard_commands.start("tcp-zx", n_points=4)
    touch(s, 2)
    sheet, md = v.math.sheet, math_md(v)
    R, f = touches_mm(s.workflow.wizard)
    check_pair(sheet, R, f, 0, 1)
    assert "normally a singular matrix and results in no solution" in md
    touch(s, 4)
    res = s.workflow.result
    assert res is not None
    sheet, md = v.math.sheet, math_md(v)
    assert [b.key for b in sheet.blocks][-3:] == ["axis-z", "axis-x", "frame"]
    R, f = touches_mm(s.workflow.wizard, [0, 1, 2, 3])
    t, r = lstsq_4p3(R, f)
    np.testing.assert_allclose(value(sheet, "lstsq", "t_lstsq"), res.tcp_mm, atol=1e-12)
    np.testing.assert_allclose(res.tcp_mm, t, atol=1e-8)
    (Rz,), (fz,) = touches_mm(s.workflow.wizard, [4])
    (Rx,), (fx,) = touches_mm(s.workflow.wizard, [5])
    vz, vx = Rz.T @ (r - fz) - t, Rx.T @ (r - fx) - t
    np.testing.assert_allclose(value(sheet, "axis-z", "v"), vz, atol=1e-7)
    np.testing.assert_allclose(value(sheet, "axis-x", "v"), vx, atol=1e-7)
    assert float(value(sheet, "axis-z", "d")) == pytest.approx(np.linalg.norm(vz), abs=1e-7)
    z, xm = vz / np.linalg.norm(vz), vx / np.linalg.norm(vx)
    defect = abs(90.0 - math.degrees(math.acos(float(xm @ z))))
    assert float(value(sheet, "frame", "defect")) == pytest.approx(defect, abs=1e-6)
    assert defect == pytest.approx(res.orthogonality_defect_deg, abs=1e-6)
    x = xm - (xm @ z) * z
    x /= np.linalg.norm(x)
    np.testing.assert_allclose(value(sheet, "frame", "R_flange_tool"), np.column_stack([x, np.cross(z, x), z]),
                               atol=1e-9)
    np.testing.assert_allclose(value(sheet, "frame", "R_flange_tool"), res.rotation, atol=1e-9)   # the solver's
    assert_text_is_the_numbers(md, sheet)


# ------------------------------------------------------------------ beam
def test_beam_math_stacks_the_tip_events(page) -> None:
    p = page()
    v, s = p.view, p.session
    with s.lock:
        s.wizard_commands.start("beam")
    assert v.math.folder.visible and v.math.sheet.blocks == ()
    with s.lock:
        s.wizard_commands.next_step()                               # the controller runs the scan
    res = s.workflow.result
    assert res is not None
    sheet, md = v.math.sheet, math_md(v)
    tips = [res.events[i] for i in res.tip_event_indices]
    rows, rhs = [], []
    for e in tips:
        u = e.beam_dir
        P = np.eye(3) - np.outer(u, u)
        rows.append(P @ e.T_world_flange[:3, :3])
        rhs.append(-P @ (e.T_world_flange[:3, 3] - e.beam_point) * 1000.0)
    A, y = np.vstack(rows), np.concatenate(rhs)
    np.testing.assert_allclose(value(sheet, "stack", "sigma"), np.linalg.svd(A, compute_uv=False), atol=1e-9)
    assert "rank 3 of 3" in shown_blocks(md)["stack"]
    t, *_ = np.linalg.lstsq(A, y, rcond=None)
    np.testing.assert_allclose(value(sheet, "stack", "t"), t, atol=1e-6)
    np.testing.assert_allclose(value(sheet, "event-1", "f_i"), tips[0].T_world_flange[:3, 3] * 1000.0, atol=1e-9)
    assert escape_markdown("(BEAM-1)") in md
    assert_text_is_the_numbers(md, sheet)


def test_every_registered_method_declares_a_math_view() -> None:
    from tcp_pendant.calibrate.math_view import MATH_VIEWS
    from tcp_pendant.wizards import wizard_classes

    for cls in wizard_classes():
        assert cls.math_view in MATH_VIEWS, cls.kind


def test_a_wizard_without_a_math_view_has_no_sheet() -> None:
    class Plain:
        math_view = None
        title = "Plain"

    assert math_sheet(Plain()) is None


# ------------------------------------------------------------------ TCP check (spin test)
def test_spin_check_math_bounds_the_drifts_by_the_tcp_error(page) -> None:
    p = page(tool="torch")
    v, s = p.view, p.session
    tcp, _, abc = true_frame("torch")
    off = np.array([0.6, -0.48, 0.64])                              # 1 mm off in FLANGE
    s.library.save(1, Tool(name="Off", tcp_mm=tuple(float(x) for x in tcp + off),
                           abc_deg=tuple(float(x) for x in abc)))
    with s.lock:
        s.wizard_commands.start("tcp-check", slot=1)
        assert s.wizard_commands.auto_touch(AutoTouchRequest(tilt_deg=25.0, azimuth_deg=30.0)).ok
        s.wizard_commands.next_step()                                               # the six spins, here synchronously
    check = s.workflow.result.check
    sheet, md = v.math.sheet, math_md(v)
    drifts = [r.deviation_mm for r in check.rows if r.reached]
    np.testing.assert_allclose(value(sheet, "spin", "drifts"), drifts, atol=0)
    e = check.implied_tcp_error_mm
    assert e == pytest.approx(1.0, abs=0.05)
    bound = float(value(sheet, "spin", "bound"))
    assert bound == pytest.approx(2.0 * math.sin(math.radians(15.0)) * e, abs=1e-12)
    assert max(drifts) <= bound + 0.01                              # methods.md section 10
    assert_text_is_the_numbers(md, sheet)
