"""The verification every program passes before it leaves (surfmod/cam/verify.py).

The verifier must find what is wrong with a program, so most tests here break a good
program on purpose and ask it to say what, where and on which line: a move lowered into
the part (its depth measured exactly: a ball sunk into a plane), a rapid run through the
stock, finishing lifted off the part (the scallop promise broken).  The good programs
pass; on ``step_samples/cam_part.step`` the residual it measures is the one the issue's
independent judge measured (0.024 mm for a 0.03 mm scallop; in the corpus run).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import build123d as bd
import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial import cKDTree
from stock_sim import Cutter, Stock, parse_gcode, part_height, reachable, side_grids, simulate, vertex_normals, \
    wall_left, wall_points
from twins.program_lines import read_program_lines

import surfmod as sm
from surfmod.cam import part_points as P
from surfmod.cam import verify as V
from surfmod.cam import wall_dexels as W
from surfmod.cam.cutters import Bull
from surfmod.cam.drop_cutter import part_triangles
from surfmod.cam.job import _relink
from surfmod.cam.roughing import PLUNGE, RAPID, Motion
from surfmod.cam.program import read_program
from surfmod.cam.post import programs
from surfmod.cli import main
from surfmod.errors import SurfmodError
from surfmod.inputs import to_shape

SAMPLES = Path(__file__).resolve().parent.parent / "step_samples"
TOP = 2.5  # the boss part's box top


def boss_part():
    return bd.Box(20, 20, 5) + bd.Pos(0, 0, 4) * bd.Cylinder(5, 3)


@pytest.fixture(scope="module")
def job():
    return sm.machine(boss_part(), 2.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=2.0, allowance=0.3),
                                         sm.Finish(sm.Tool("ball", 1.5), scallop=0.05)])


def _finding(v, word):
    return next(f for f in v.findings if f.what.startswith(word))


# -- the program reader ------------------------------------------------------------------------
def test_arcs_become_chords_inside_the_arc():
    text = "T1 M6\nS1000 M3\nG0 X10 Y0 Z1\nG1 Z0 F100\nG3 X-10 Y0 I-10 J0\nG2 X10 Y0 Z-1 I10 J0\nM5\nM30"
    moves = read_program(text, chord=1e-4)
    arc = moves.line == 5
    r = np.hypot(moves.end[arc, 0], moves.end[arc, 1])
    # CCW from (10, 0) to (-10, 0): over the top, x falling
    assert np.allclose(r, 10.0, atol=1e-12) and np.all(moves.end[arc, 1] >= -1e-12)
    assert np.all(np.diff(moves.end[arc, 0]) < 0)
    mid = 0.5 * (moves.start[arc] + moves.end[arc])
    sag = 10.0 - np.hypot(mid[:, 0], mid[:, 1])
    assert 0 < sag.max() <= 1e-4 and arc.sum() == math.ceil(math.pi / (2 * math.acos(1 - 1e-4 / 10)))
    cw = moves.line == 6
    # CW from (-10, 0) back to (10, 0) round the same centre: over the top again, x rising,
    # down a helix to Z-1
    assert np.all(moves.end[cw, 1] >= -1e-12) and np.all(np.diff(moves.end[cw, 0]) > 0)
    assert np.all(np.diff(moves.end[cw, 2]) < 0) and moves.end[cw, 2][-1] == -1.0
    assert moves.spindle[arc].all() and not moves.rapid[arc].any() and set(moves.tool) == {1}


@pytest.mark.parametrize("text, word", [
    ("G0 X0 Y0 Z1\nG91 G1 X1", "G91"),
    ("G20\nG0 X1", "G20"),
    ("G0 X0 Y0 Z0\nG2 X1 Y1 I1", "I and J"),
    ("X1 Y1", "before any G0"),
    ("G0 X1 Q5", "Q5"),
    ("G0 X1 Y1 Z1\nM98", "M98"),
])
def test_words_outside_the_dialect_name_their_line(text, word):
    with pytest.raises(SurfmodError, match=r"program: line \d+") as err:
        read_program(text)
    assert word in str(err.value)


def _read(reader, text, tool=0):
    """What a reader makes of ``text``: its moves, or the message it refuses it with."""
    try:
        return reader(text, tool=tool)
    except SurfmodError as err:
        return str(err)


def _same_reading(a, b):
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    return all(np.array_equal(getattr(a, f), getattr(b, f)) and getattr(a, f).dtype == getattr(b, f).dtype
               for f in ("start", "end", "rapid", "tool", "spindle", "line"))


#: lines a random program is drawn from: the posts' own, what an operator may type
#: (lower case, spaces, comments, %), and what is outside the dialect
_LINES = ["G0 Z{z}", "G0 X{x} Y{y}", "G1 X{x} Y{y} Z{z} F300", "G1 X{x}", "g1 y {y} z{z}", "X{x} Y{y}",
          "G2 X{x} Y{y} I{i} J{j}", "G3 X{x} Y{y} Z{z} I{i} J{j} F200", "G3 X{x} Y{y} I{i}", "G2 X{x} Y{y}",
          "T{t} M6", "M6 T{t}", "T{t}", "G43 H{t}", "S1000 M3", "M5", "M3 M5 M3", "M8", "M9", "%", "", "  \t ",
          "(operation: roughing)", "G1 X{x} (a comment) Y{y} ; and a tail", "N10 G1 Z{z}", "G21 G90 G17 G94",
          "G0 X{x} G1 Y{y}", "G0 X{x} X{y}", "G20", "G91 G1 X{x}", "Q5", "M98", "X1..2", "G1 X{x} \tY{y}",
          "\tG1 Z{z}\t", "% %", "G01 X{x}", "G1.0 Y{y}", "M30", "G1 X+{x} Y.5", "G1 X{x}Y{y}Z{z}"]


def test_the_whole_text_reader_reads_as_a_controller_line_by_line(job):
    """The reader takes the words of the whole text at once and carries the modes as
    arrays; a reader of one line at a time (its former self) gives the same moves bit for
    bit, and for a program outside the dialect the same message on the same line, on the
    job's program and on 400 random ones that mix the posts' lines with typed and broken ones."""
    text = programs(job)[0]
    assert len(read_program(text)) > 10_000 and _same_reading(read_program(text), read_program_lines(text))
    rng = np.random.default_rng(36)
    refused = 0
    for _ in range(400):
        lines = []
        for _ in range(int(rng.integers(1, 40))):
            # the broken lines a few times in a program at most
            k = int(rng.integers(len(_LINES) if rng.random() < 0.05 else _LINES.index("G20")))
            x, y, z, i, j = (f"{v:.4f}" for v in rng.uniform(-20, 20, 5))
            lines.append(_LINES[k].format(x=x, y=y, z=z, i=i, j=j, t=int(rng.integers(1, 4))))
        text = "\n".join(lines)
        tool = int(rng.integers(3))
        a, b = _read(read_program, text, tool), _read(read_program_lines, text, tool)
        assert _same_reading(a, b), (text, a, b)
        refused += isinstance(a, str)
    assert 40 < refused < 360  # both kinds of program were drawn


# -- verdicts ------------------------------------------------------------------------------------
def test_a_made_job_passes(job):
    v = job.verification
    assert v is not None and v.ok, str(v)
    assert [f.what.split(" (")[0] for f in v.findings] == ["gouge, roughing", "gouge, finishing", "rapids",
                                                           "holder and shank, roughing",
                                                           "holder and shank, finishing", "residual after finishing",
                                                           "residual on walls after finishing"]
    residual = _finding(v, "residual")
    assert 0.5 * 0.05 < residual.worst <= residual.limit  # cusps are there, within the scallop
    assert v.samples > 50_000 and v.probes > 50_000 and v.nodes > 10_000
    assert "verified against the exact part" in str(job)


def _tampered(job, pattern, replacement, count=1):
    text = programs(job)[0]
    new, n = re.subn(pattern, replacement, text, count=count, flags=re.M)
    assert n == count
    return text, new


def _lowered(job):
    """The job's program with a finishing move ending on the box top (z 2.5) clear of the
    boss and the box's edges (so the plane alone is in reach) sunk about 0.5 into it there,
    then back up: ``(lines, line index, x, y, depth sunk)``."""
    text = programs(job)[0]
    moves = read_program(text)
    lines = text.splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("(operation: finishing")) + 1
    x, y, z = moves.end.T
    ok = ((moves.line > start) & ~moves.rapid & (np.abs(z - TOP) < 0.01) & (np.maximum(abs(x), abs(y)) <= 8)
          & (np.hypot(x, y) >= 7.5))
    assert ok.any()
    m = int(np.argmax(ok))
    k = int(moves.line[m]) - 1
    assert lines[k].startswith("G1 ")
    lines[k] = re.sub(r" Z-?[\d.]+", "", lines[k]) + f" Z{z[m] - 0.5:.4f}"
    lines.insert(k + 1, f"G1 Z{z[m]:.4f}")
    return lines, k, x[m], y[m], 0.5 - (z[m] - TOP)


def test_a_move_lowered_into_the_part_is_a_gouge_measured_exactly(job):
    lines, k, x, y, sunk = _lowered(job)
    v = V.verify_job(job, texts=["\n".join(lines)])
    gouge = _finding(v, "gouge, finishing")
    assert not v.ok and not gouge.ok and gouge.line in (k + 1, k + 2)
    # the deepest point: the ball's centre 1.5 - sunk above the plane (OCCT's distance)
    assert abs(gouge.worst - sunk) < 1e-9, gouge
    assert abs(gouge.where[2] - TOP) < 1e-9 and math.hypot(gouge.where[0] - x, gouge.where[1] - y) < 1.5
    assert _finding(v, "gouge, roughing").ok


def test_a_verdict_after_a_repair_measures_the_changed_stretch_again(job, monkeypatch):
    # given the verdict before (as the job's repair gives it), the moves it measured
    # against the part are taken from it: the lowered move and the one after it are
    # measured again, and the verdict is the one judged from scratch
    lines, k, *_ = _lowered(job)
    fresh = V.verify_job(job, texts=["\n".join(lines)])
    before = V.verify_job(job)
    assert not job.verification.measured  # the job keeps none of it
    # the verdict before holds how the part was sampled, not its points: sampled again
    # (the kept sampling dropped, a verdict samples anew), the part's measures are still its
    P._SAMPLED.clear()
    V.verify_job(job)
    probed, swept = [], []
    probes, sweep = V.probes_along, V.K.sweep_body
    monkeypatch.setattr(V, "probes_along", lambda *a: probed.append(len(a[0])) or probes(*a))
    monkeypatch.setattr(V.K, "sweep_body", lambda *a: swept.append(len(a[4])) or sweep(*a))
    again = V.verify_job(job, texts=["\n".join(lines)], before=before)
    assert [str(f) for f in again.findings] == [str(f) for f in fresh.findings]
    assert not _finding(again, "gouge, finishing").ok and again.probes == fresh.probes
    # the checks along the moves probed the two changed moves alone (one stretch a check)
    assert probed and max(probed) <= 2 and fresh.probes > 50_000
    # the stock was swept again from the last stock kept before the lowered move, not from the start
    moves = read_program("\n".join(lines))
    assert 0 < sum(swept) <= (moves.line > k).sum() + len(moves) / V.SWEEP_MARKS + 1
    # and the whole program swept at once finds what the stretches found
    monkeypatch.setattr(V, "SWEEP_MARKS", 1)
    whole = V.verify_job(job, texts=["\n".join(lines)])
    assert [str(f) for f in whole.findings] == [str(f) for f in fresh.findings]


def test_a_rapid_through_the_stock_is_found(job):
    # after the roughing's first G0 to the safe height, a rapid across the uncut block
    text = programs(job)[0]
    lines = text.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("T1 M6")) + 2
    lines.insert(k + 1, "G0 X-11.0000 Y-11.0000 Z7.0000")
    lines.insert(k + 2, "G0 X11.0000 Y11.0000 Z7.0000")
    v = V.verify_job(job, texts=["\n".join(lines)])
    rapids = _finding(v, "rapids")
    assert not rapids.ok and rapids.line in (k + 2, k + 3), rapids
    assert rapids.worst == pytest.approx(7.5 - 7.0, abs=1e-9)  # the stock's top: 2 above the part's 5.5


def test_finishing_lifted_off_the_part_breaks_the_scallop(job):
    text = programs(job)[0]
    head, tail = text.split("(operation: finishing", 1)
    lifted = re.sub(r"Z(-?\d+\.\d+)", lambda m: f"Z{float(m.group(1)) + 0.2:.4f}", tail)
    v = V.verify_job(job, texts=[head + "(operation: finishing" + lifted])
    residual = _finding(v, "residual")
    assert not residual.ok and residual.worst > 0.19 and residual.count > 1000, residual
    assert _finding(v, "gouge, finishing").ok


def test_grbl_programs_are_read_per_tool(job):
    v = V.verify_job(job, post="grbl")
    assert v.ok and [f.what for f in v.findings] == [f.what for f in job.verification.findings]
    with pytest.raises(SurfmodError, match="programs: expected 2 GRBL programs"):
        V.verify_job(job, post="grbl", texts=programs(job, "grbl")[:1])


def test_work_is_bounded_up_front(job):
    with pytest.raises(SurfmodError, match="max_samples"):
        P.part_points(job.part, 0.01, max_samples=1000)
    moves = sum(len(op.motion.points) for op in job.operations)
    with pytest.raises(SurfmodError, match="max_probes"):  # not even two probes per move
        V.verify_job(job, max_probes=moves)
    # points, probes and stock cells fit their caps instead, coarser, and the verdict says so
    full = job.verification.probes
    v = V.verify_job(job, max_samples=20_000, max_nodes=2_000, max_probes=full // 2, max_dexel_work=200_000)
    assert v.samples <= 20_000 and v.nodes <= 2_000 and v.spacing > job.verification.spacing
    assert v.probes <= full // 2
    assert any("coarser than" in n and "points" in n for n in v.notes)
    assert any("probes" in n and "coarser than" in n for n in v.notes)
    assert any("stock cells" in n for n in v.notes)
    assert any(n.startswith("note: walls: dexels") and "coarser than" in n for n in v.notes)
    assert 0 < v.dexels < job.verification.dexels


@pytest.mark.corpus
def test_cam_part_residual_is_the_judges():
    """At the issue's 0.03 scallop (10 CPU seconds: in the corpus run); the default run
    holds the verdict's residual to the independent judge's on the proof's job at 0.15
    (``test_cam_job_proof.py::test_cam_part_job_in_stock``)."""
    job = sm.machine(str(SAMPLES / "cam_part.step"), 2.0,
                     [sm.Rough(sm.Tool("flat", 4.0, flute_length=80), allowance=0.5),
                      sm.Finish(sm.Tool("ball", 3.0, flute_length=80), scallop=0.03)])
    v = job.verification
    assert v.ok, str(v)
    residual = _finding(v, "residual")
    assert 0.02 < residual.worst <= residual.limit < 0.035, residual


# -- walls ----------------------------------------------------------------------------------------
def _one_move(start, end, radius, corner, swap, cell=0.1):
    """Dexels over the box [-5, 5]² x [0, 4] after one feed move: the intervals of each."""
    from surfmod.cam import wall_dexels as W

    order = [1, 0, 2] if swap else [0, 1, 2]
    a, b = (np.array([p], float)[:, order] for p in (start, end))
    lines, levels = int(10 / cell) + 1, int(4 / cell)
    seg = np.zeros((lines, levels, W.SEGMENTS, 2))
    seg[:, :, 0] = -5.0, 5.0
    cnt = np.ones((lines, levels), np.int64)
    full = W.sweep_dexels(seg, cnt, np.zeros(lines, np.int64), np.full(lines, levels - 1), -5.0, 0.0, cell, a, b,
                          np.zeros(1, bool), np.array([radius]), np.array([corner]), cell / 2)
    assert full == 0
    return seg, cnt


def test_dexels_lose_the_tools_exact_section():
    # a ball along x at y = 0.3, tip at z 1: the dexel along y through x = 0 (a stamp's own
    # place) loses the ball's section at each level, then the cylinder's
    seg, cnt = _one_move((-3, 0.3, 1), (3, 0.3, 1), 1.5, 1.5, swap=True)
    for k in range(40):
        h = (k + 0.5) * 0.1 - 1.0
        r = 0.0 if h <= 0 else 1.5 if h >= 1.5 else math.sqrt(1.5 ** 2 - (1.5 - h) ** 2)
        got = np.sort(seg[50, k, :cnt[50, k]], axis=0)
        want = [[-5.0, 5.0]] if r == 0 else [[-5.0, 0.3 - r], [0.3 + r, 5.0]]
        assert np.allclose(got, want, atol=1e-12), (k, got, want)
    # a flat end on a diagonal: above its tip the capsule round the move, exactly (against
    # discs 1e-4 apart along it)
    seg, cnt = _one_move((0, 0, 1), (3, 4, 1), 2.0, 0.0, swap=False)
    t = np.linspace(0, 1, 50_001)
    for j in range(0, 101, 7):
        y = -5 + 0.1 * j
        d = y - 4 * t
        inside = np.abs(d) < 2.0
        half = np.sqrt(np.maximum(4.0 - d * d, 0.0))
        lo, hi = (3 * t - half)[inside].min(initial=np.inf), (3 * t + half)[inside].max(initial=-np.inf)
        got = np.sort(seg[j, 15, :cnt[j, 15]], axis=0)
        want = [[-5.0, 5.0]] if lo > hi else [[-5.0, lo], [hi, 5.0]]
        assert np.allclose(got, want, atol=1e-6), (j, got, want)


def test_the_walls_feet_do_not_depend_on_the_order_of_the_parts_points():
    """The part's points in another order give the walls' judge the same points in the
    same order, so the nearest points and planes of the stock points break their ties
    alike and the feet are equal bit for bit: the verdict is a function of the points.
    Points of equal height in a bucket used to keep the order they came in (a pocket's
    floor, a plane of points on a grid: 8 nearest among equal distances): shuffled, 39 of
    these 4,000 depths changed (up to 1.6 mm, a far point's coarse nearest) and 5 points
    whether they stand on a wall."""
    part = bd.Box(30, 30, 10) - bd.Pos(0, 0, 2) * bd.Box(16, 16, 6.01)
    points, _ = P.part_points(part, 0.25)
    rng = np.random.default_rng(5)
    buckets = [P.PartPoints.bucket(p, 1.0) for p in (points, points[rng.permutation(len(points))])]
    assert np.array_equal(buckets[0].points, buckets[1].points)
    # stock points before the pocket's walls and over its floor, some far from the part
    q = np.column_stack([rng.uniform(-8, 8, 4000), rng.uniform(6.5, 8.0, 4000), rng.uniform(-3.0, 6.0, 4000)])
    feet = []
    for b in buckets:
        near = b.around(q, 2)
        feet.append(W.feet(cKDTree(near), near, q, b.cell / 4, 0.5))
    assert all(np.array_equal(x, y) for x, y in zip(*feet))
    assert W.steep_normals(feet[0][1]).sum() > 1000


def test_a_stock_point_on_a_bores_axis_is_measured_from_its_wall():
    # points 0.3 apart on a bore of radius 20; stock points within 0.5 of its axis are as
    # far from a whole ring of them: the 8 nearest of the exact query lie round the ring,
    # and the plane through them passes near the axis (depth 0.1 where it is 19.5).  Taken
    # from the patch round the nearest of the points one per 1.5 mm voxel, the depth is
    # the bore's radius to within the sag of the patch's points; a point nearer the wall
    # than ``far`` keeps the exact query
    r, s = 20.0, 0.3
    t, z = np.meshgrid(np.arange(0, 2 * np.pi, s / r), np.arange(-30, 30, s))
    ring = np.column_stack([r * np.cos(t).ravel(), r * np.sin(t).ravel(), z.ravel()])
    rng = np.random.default_rng(3)
    q = np.column_stack([rng.uniform(-19.5, 19.5, 400), rng.normal(0, 0.5, 400), rng.uniform(-10, 10, 400)])
    tree = cKDTree(ring)
    depth, normal, foot = W.feet(tree, ring, q, 1.5, 6.0)
    true = r - np.hypot(q[:, 0], q[:, 1])
    assert np.all(depth >= true - 0.01) and np.all(depth <= true + 0.02)
    assert np.allclose(np.hypot(foot[:, 0], foot[:, 1]), r, atol=0.02) and np.abs(normal[:, 2]).max() < 0.02
    exact = W.feet(tree, ring, q)[0]
    wall = true < 6.0 - 1.5 * math.sqrt(3)
    assert np.array_equal(depth[wall], exact[wall]) and np.abs(exact - true).max() > 10


DRAFT, CONE_H, BALL = 10.0, 6.0, 1.5  # a cone boss 6 high whose wall leans 10 degrees in


@pytest.fixture(scope="module")
def cone_job():
    top = 5.0 - CONE_H * math.tan(math.radians(DRAFT))
    part = bd.Box(20, 20, 5) + bd.Pos(0, 0, 2.5 + CONE_H / 2) * bd.Cone(5, top, CONE_H)
    return sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=2.0, allowance=0.3),
                                  sm.Finish(sm.Tool("ball", BALL), scallop=0.05)])


def _cone_contours(lines: list[str], start: int) -> dict:
    """The waterline contours round the cone after line ``start``: by tip height, the lines
    setting it and the contour's distance from the cone's axis (the moves after such a
    line run in x and y alone)."""
    found, z, zline, run = {}, None, None, []

    def close():
        r = np.hypot(*np.array(run).T) if len(run) > 5 else np.zeros(1)
        if 3.5 < r.min() and r.max() < 7.5:
            lines_, radii = found.setdefault(z, ([], []))
            lines_.append(zline)
            radii.append(float(r.mean()))

    for i in range(start, len(lines)):
        g = re.fullmatch(r"G1(?: X(-?[\d.]+))?(?: Y(-?[\d.]+))?(?: Z(-?[\d.]+))?(?: F\d+)?", lines[i])
        if g and g[3] is None and z is not None and (g[1] or g[2]):
            last = run[-1] if run else (math.nan, math.nan)
            run.append((float(g[1]) if g[1] else last[0], float(g[2]) if g[2] else last[1]))
            continue
        close()
        run = []
        z, zline = (float(g[3]), i) if g and g[3] else (None, None)
    return found


def _left_on_cone(levels: dict, z: np.ndarray) -> np.ndarray:
    """The textbook: material on the cone's wall at heights ``z``, measured along its
    normal, that a ball end on its cylinder leaves from the contours at ``levels`` (tip
    height: distance of the axis from the cone's), each in the meridian plane of its
    contact: the ball below its equator, the cylinder's side above it."""
    lean = math.radians(DRAFT)
    n = np.array([math.cos(lean), math.sin(lean)])  # the wall's outward normal (r, z)
    p = np.column_stack([5.0 - (z - 2.5) * math.tan(lean), z])
    left = np.full(len(z), np.inf)
    for tip, axis in levels.items():
        centre = np.array([axis, tip + BALL])
        d = p - centre
        b, c = d @ n, np.einsum("ij,ij->i", d, d) - BALL ** 2
        ball = np.where(b * b >= c, -b - np.sqrt(np.maximum(b * b - c, 0.0)), np.inf)
        ball = np.where(p[:, 1] + ball * n[1] <= centre[1], ball, np.inf)
        side = (axis - BALL - p[:, 0]) / n[0]
        side = np.where(p[:, 1] + side * n[1] >= centre[1], side, np.inf)
        left = np.minimum(left, np.maximum(np.minimum(ball, side), 0.0))
    return left


def test_a_clean_job_leaves_its_scallop_on_a_leaning_wall(cone_job):
    v = cone_job.verification
    assert v.ok, str(v)
    wall = _finding(v, "residual on walls")
    # the waterline's cusps are there, within the scallop: 0.044 for its levels 0.72 apart
    spacing = cone_job.operations[1].report["waterline"]["spacing"]
    assert 0.5 * (BALL - math.sqrt(BALL ** 2 - (spacing / 2) ** 2)) < wall.worst <= wall.limit, wall
    assert v.dexels > 1000 and v.wall_points > 1000 and "dexels along x and y" in v.lines()[0]


def test_a_wall_cusp_left_by_every_other_waterline_level_is_measured(cone_job):
    """Every other contour round the cone lifted 2 mm off it (0.35 mm along its normal: it
    cuts nothing of the wall) and the raster left out (it climbs the cone's flanks too):
    the cusps between the contours kept are twice as high as the finishing made them, and
    the verifier measures the highest as the textbook has it, to the dexels' resolution."""
    lines = programs(cone_job)[0].splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("(operation: finishing"))
    contours = _cone_contours(lines, start)
    tips = sorted(contours, reverse=True)
    assert len(tips) >= 6
    for tip in tips[1::2]:
        for i in contours[tip][0]:
            lines[i] = re.sub(r"Z-?[\d.]+", f"Z{tip + 2.0:.4f}", lines[i])
    # the raster (the finishing's first moves): from the entry to its first point up to its
    # lift to the safe height, before the first contour
    x0, y0 = cone_job.operations[1].report["toolpath"].points[0][:2]
    first = min(i for rows, _ in contours.values() for i in rows)
    entry = min(i for i in range(start, first) if lines[i].startswith(f"G0 X{x0:.4f} Y{y0:.4f}"))
    end = min(i for i in range(entry, first) if lines[i] == f"G0 Z{cone_job.safe_height:.4f}")
    v = V.verify_job(cone_job, texts=["\n".join(lines[:entry] + lines[end + 1:])])
    wall = _finding(v, "residual on walls")
    assert not v.ok and not wall.ok and wall.count > 10, wall
    assert _finding(v, "gouge, finishing").ok
    # the textbook over the wall above the lowest contact (below it: the fillet at the floor)
    kept = {tip: float(np.mean(contours[tip][1])) for tip in tips[::2]}
    z = np.linspace(min(kept) + BALL * (1 - math.sin(math.radians(DRAFT))), 2.5 + CONE_H, 6001)
    left = _left_on_cone(kept, z)
    peak = int(np.argmax(left))
    cusp = float(left[peak])
    # the ball alone would leave 0.184 between contacts 1.44 apart on the wall; the cylinder
    # above its equator, standing off the leaning wall, cuts the cusp's top down to 0.127
    assert 0.1 < cusp < 0.18, cusp
    # the dexels stand a cell apart in z: the nearest is at most half a cell from the peak
    cell = cone_job.operations[1].report["stepover"] / 4
    near = np.abs(z - z[peak]) <= cell / 2
    assert cusp - (cusp - left[near].min()) - wall.limit / 2 <= wall.worst <= cusp + wall.limit / 2, (wall, cusp)
    assert abs(math.hypot(wall.where[0], wall.where[1]) - (5.0 - (wall.where[2] - 2.5) * math.tan(math.radians(DRAFT)))) < 0.25



LEAN = 14.0  # a boss whose wall stands 76 degrees


def test_a_bull_nose_at_a_stepover_is_held_to_its_contours_cusp():
    """A bull nose (corner 1) finishing at a stepover of 2.5 has no scallop on flat ground
    (its core spans the stepover), but its contours 2.5 apart along a 76 degree wall leave
    cusps its corner cannot close: 0.394 (``Cutter.wall_cusp``), and 0.41 measured by the
    tests' own dexels (the contours keep the mesh's deflection and a chord off it).  The
    walls' verdict is held to the cusp of such contours on a 70 degree wall (0.525), no
    longer to the raster's zero cusp on flat ground (it was 0.34 against 0.042: broken)."""
    part = (bd.Box(30, 30, 3, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MAX))
            + bd.Cone(7.5, 7.5 - 10 * math.tan(math.radians(LEAN)), 10.0,
                      align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)))
    job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0), allowance=0.5),
                                 sm.Finish(sm.Tool("bull", 3.0, 1.0), stepover=2.5)])
    v, report = job.verification, job.operations[1].report
    assert v.ok, str(v)
    assert report["scallop"] == 0.0 and report["waterline"]["spacing"] == 2.5
    # the contours' levels, 2.42 apart in z: 2.5 along the wall
    along = report["waterline"]["z_spacing"][1] / math.sin(math.radians(90 - LEAN))
    cusp = Bull(3.0, 1.0).wall_cusp(along, 90 - LEAN)
    assert 0.39 < cusp < 0.40 and along == pytest.approx(2.5, abs=0.01)
    wall = _finding(v, "residual on walls")
    assert wall.limit == pytest.approx(Bull(3.0, 1.0).wall_cusp(2.5, W.DEXEL_SLOPE) + float(report["tolerance"]),
                                       abs=0.02)
    # the verifier's dexels a cell (0.6 mm) apart in z see the cusps' crests lower
    assert 0.75 * cusp < wall.worst <= wall.limit, (wall, cusp)
    # the tests' own dexels 0.05 apart over one side of the wall, cut by every feed move
    text = programs(job)[0]
    moves = [m for m in parse_gcode(text).moves if not m.rapid]
    tri, _, (_, owner) = part_triangles(part, 0.002, face_index=True)
    box = np.array([[-1.0, -8.0, 1.5], [1.0, -5.0, 9.5]])
    sides = side_grids(box, 0.05)
    for number, cutter in ((1, Cutter("flat", 3.0)), (2, Cutter("bull", 3.0, 1.0))):
        a, b = (np.array([getattr(m, e) for m in moves if m.tool == number]) for e in "ab")
        near = (np.all(np.minimum(a, b)[:, :2] <= box[1, :2] + cutter.radius, axis=1)
                & np.all(np.maximum(a, b)[:, :2] >= box[0, :2] - cutter.radius, axis=1))
        a, b = a[near], b[near]
        for dex in sides:
            dex.cut(cutter, a, b)
    left = np.concatenate([wall_left(dex, wall_points(tri, dex, steep=60.0, normals=vertex_normals(tri, owner)))
                           for dex in sides])
    margin = report["waterline"]["margin"]
    assert cusp < np.nanmax(left) <= cusp + margin + 0.01 < wall.limit, (np.nanmax(left), cusp)


@pytest.mark.parametrize("cutter", [Bull(3.0, 1.0), Bull(2.0, 0.5), sm.Tool("ball", 1.0).cutter,
                                    sm.Tool("flat", 3.0).cutter])
def test_a_wall_cusp_is_the_tools_section_measured_point_by_point(cutter):
    """``Cutter.wall_cusp`` against the tool's section drawn as a polygon (its corner's arc
    in 400 chords, the flanks up to 20 mm) and measured off the wall at 4,001 points
    between the two positions and as many round the highest: the lower of the two near
    sides, at its highest."""
    c, core = cutter.corner, cutter.core
    arc = np.linspace(-np.pi / 2, 0, 400)
    right = np.column_stack([core + c * np.cos(arc), c + c * np.sin(arc)])
    section = np.concatenate([right, [[cutter.radius, 20.0], [-cutter.radius, 20.0]], right[::-1] * [-1, 1]])
    assert cutter.wall_cusp(2.5, 90.0) == 0.0  # on a vertical wall the flank sweeps all between
    for slope in (45.0, 70.0, 76.0, 85.0, 89.5):
        for spacing in (0.5, 1.5, 2.5):
            beta = math.radians(90.0 - slope)
            d = section @ [-math.cos(beta), math.sin(beta)]
            t = section @ [math.sin(beta), math.cos(beta)]
            k = int(np.argmin(d))
            d, t = d - d[k], t - t[k]
            e0, e1 = np.c_[t, d], np.roll(np.c_[t, d], -1, axis=0)

            def near(x):
                lo, hi = np.minimum(e0[:, 0], e1[:, 0]), np.maximum(e0[:, 0], e1[:, 0])
                on = (x[:, None] >= lo) & (x[:, None] <= hi) & (hi > lo)
                w = (x[:, None] - e0[:, 0]) / np.where(hi > lo, e1[:, 0] - e0[:, 0], 1.0)
                return np.where(on, e0[:, 1] + w * (e1[:, 1] - e0[:, 1]), np.inf).min(axis=1)

            x = np.linspace(0.0, spacing, 4001)
            top = x[np.argmax(np.minimum(near(x), near(x - spacing)))]
            x = np.linspace(top - spacing / 4000, top + spacing / 4000, 4001)  # again round the crest
            want = float(np.max(np.minimum(near(x), near(x - spacing))))
            # the chords lie inside the arc by at most 8e-6 mm
            assert cutter.wall_cusp(spacing, slope) == pytest.approx(want, abs=2e-5), (slope, spacing)


# -- toolpaths -----------------------------------------------------------------------------------
def test_toolpath_judged_against_exact_faces_not_loose_wires(tmp_path, capsys):
    # the spline cage holds six loose B-spline edges (no face): construction curves, not
    # material.  OCCT's distance to the whole shape finds the ball "1.04 mm inside" them;
    # to the faces the path keeps its tolerance
    part = Path(__file__).parent / "data" / "step" / "pythonocc_splinecage.stp"
    out = tmp_path / "cage.nc"
    code = main(["toolpath", str(part), "--radius", "2", "--scallop", "0.04", "--out", str(out), "--no-progress"])
    text = capsys.readouterr().out
    assert code == 0 and "gouge: " in text and ", ok" in text, text
    shape = to_shape(part)
    path = sm.toolpath(shape, sm.Tool("ball", 2.0), scallop=0.04)
    lines = path.to_gcode().splitlines()
    k = len(lines) // 2
    z = float(re.search(r"Z(-?[\d.]+)", lines[k]).group(1))
    lines[k] = re.sub(r"Z-?[\d.]+", f"Z{z - 0.3:.4f}", lines[k])
    v = V.verify_toolpath(path, shape, text="\n".join(lines))
    assert not v.ok and v.findings[0].line == k + 1 and v.findings[0].worst > 0.25


def test_cli_machine_exit_3_and_header_on_a_broken_promise(tmp_path, capsys, monkeypatch):
    part = tmp_path / "boss.step"
    bd.export_step(boss_part(), str(part))
    args = ["machine", str(part), "--stock-margin", "2", "--rough", "flat:3", "--finish", "ball:1.5",
            "--scallop", "0.05", "--stepdown", "2", "--allowance", "0.3", "--no-progress"]
    out = tmp_path / "a.ngc"
    assert main(args + ["--out", str(out)]) == 0
    assert "(verified: gouge, roughing" in out.read_text()
    # the walls' finding in the summary and the header, with its maximum and where
    assert re.search(r"residual on walls after finishing \(tool 2, normal to the wall\): max [\d.e-]+ mm at \(",
                     capsys.readouterr().out)
    assert "residual on walls after finishing [tool 2" in out.read_text()
    out = tmp_path / "b.ngc"
    assert main(args + ["--out", str(out), "--no-verify"]) == 0
    assert "(not verified: --no-verify" in out.read_text()
    capsys.readouterr()

    real = V.verify_job

    def broken(*a, **kw):
        v = real(*a, **kw)
        bad = V.Finding("gouge, finishing (tool 2)", 0.3, 0.0051, (1.0, 2.0, 2.5), 4, 123)
        return V.Verification((bad,) + v.findings[2:], v.samples, v.probes, v.nodes, v.walls, v.spacing)

    monkeypatch.setattr("surfmod.cam.job.verify_job", broken)
    out = tmp_path / "c.ngc"
    assert main(args + ["--out", str(out)]) == 3
    captured = capsys.readouterr()
    assert out.is_file() and "(VERIFICATION FAILED: gouge, finishing [tool 2]: max 0.3 mm" in out.read_text()
    assert "BROKEN: 4 beyond it" in captured.out and "exit 3" in captured.err


# -- the repair ----------------------------------------------------------------------------------
def test_a_low_rib_along_the_raster_is_recut_and_both_judges_agree(monkeypatch):
    """A rib 1 mm high running along the raster: the ball rolls over its edges, and the
    passes along x stand too far apart on the slopes it leaves there (0.16 mm of cusps for
    a 0.05 scallop).  The verifier finds the strips, cross passes re-cut them, the job is
    judged again, and the tests' own simulation measures the same.  The part's top under
    the stock model is computed once per operation, the repair reusing the finishing's."""
    from surfmod.cam.rest import StockModel

    tops = []
    part_top = StockModel.part_top
    monkeypatch.setattr(StockModel, "part_top", lambda self, tri: tops.append(len(tri)) or part_top(self, tri))
    part = bd.Box(40, 30, 5) + bd.Pos(0, 4, 3.0) * bd.Box(40, 6, 1.0)
    job = sm.machine(part, 1.0, [sm.Rough(sm.Tool("flat", 4.0), allowance=0.3),
                                 sm.Finish(sm.Tool("ball", 3.0), scallop=0.05)])
    fin = job.operations[1]
    residual = _finding(job.verification, "residual")
    assert fin.report["recut"]["before"] > 2 * residual.limit and fin.report["recut"]["passes"] > 10
    assert job.verification.ok, str(job.verification)
    assert len(tops) == 2, tops

    simulated = _simulated_residual(job, {1: Cutter("flat", 4.0), 2: Cutter("ball", 3.0)}, 80)
    assert simulated <= residual.limit + 0.005, simulated
    assert abs(simulated - residual.worst) < 0.01, (simulated, residual.worst)


def _simulated_residual(job, cutters: dict, steepest: float) -> float:
    """The most the tests' own stock simulation (0.1 mm cells) leaves of ``job``'s program
    normal to what the last tool (a ball r = 3) can reach, on ground up to ``steepest``
    degrees, two cells in from the outline."""
    stock = Stock(job.stock, 0.1)
    tri, _ = part_triangles(job.part, 0.002)
    top = part_height(tri, stock.x, stock.y)
    simulate(parse_gcode(programs(job)[0]), cutters, stock, top)
    reach = np.maximum(reachable(np.where(np.isfinite(top), top, job.stock[0, 2]), Cutter("ball", 3.0), 0.1), top)
    gx, gy = np.gradient(reach, 0.1)
    cos = 1 / np.sqrt(1 + gx * gx + gy * gy)
    judged = ndimage.binary_erosion(np.isfinite(top), iterations=2) & (cos > math.cos(math.radians(steepest)))
    return float(((stock.top - reach) * cos)[judged].max())


def test_beside_a_step_at_a_walls_foot_the_repair_adds_passes_along_the_raster():
    """A rib 2 mm high along x butting into a 65 degree wall the raster runs up, all tilted
    8 degrees (no floor for a contour level): beside the rib, at the wall's foot, the
    ground the ball leaves is its own side, made by one position at a corner of its
    drop-cutter surface (HEAD_BACK's seam step, 0.215 against 0.166).  Cross passes alone
    miss that position along the wall's slope and left 0.065 (limit 0.056); passes along
    the raster between the finishing's hold it, and the tests' simulation agrees."""
    run = math.tan(math.radians(25.0)) * 10  # the wall's run over its 10 mm rise
    wall = bd.extrude(bd.make_face(bd.Plane.XZ * bd.Polyline((0, 0), (run, 10), (20, 10), (20, 0), close=True)),
                      amount=15, both=True)
    low = (bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)
    part = bd.Rot(0, 8, 0) * (bd.Box(40, 30, 5, align=low) + wall + bd.Pos(0, 4, 0) * bd.Box(40, 6, 7, align=low))
    job = sm.machine(part, 1.0, [sm.Finish(sm.Tool("ball", 3.0), scallop=0.05)])
    fin = job.operations[0]
    residual = _finding(job.verification, "residual after")
    assert fin.report["recut"]["before"] > 2 * residual.limit
    assert job.verification.ok, str(job.verification)

    simulated = _simulated_residual(job, {1: Cutter("ball", 3.0)}, 60)
    assert simulated <= residual.limit + 0.005, simulated


def test_a_rapid_through_the_stock_is_relinked_over_it(job):
    """A rapid across the uncut block (the roughing's motion doctored as the issue's
    keyboard case came out) is found, then re-linked by sm.machine's repair: up to the safe
    height, across, down at the plunge feed; judged again, every promise holds, and the
    tests' own stock simulation of the new program sees no rapid remove material."""
    rough = job.operations[0]
    pts, kind = rough.motion.points, rough.motion.kind
    first = int(np.argmax(kind != RAPID))  # the rapids before the first cut stay above the stock
    low = np.array([[-11.0, -11.0, 7.0], [11.0, 11.0, 7.0]])
    doctored = Motion(np.insert(pts, first, low, axis=0), np.insert(kind, first, [RAPID, RAPID]))
    bad = replace(job, operations=(replace(rough, motion=doctored),) + job.operations[1:])
    bad = replace(bad, verification=V.verify_job(bad))
    rapids = _finding(bad.verification, "rapids")
    assert not rapids.ok and len(rapids.segments) >= 1 and rapids.worst == pytest.approx(0.5, abs=1e-9)
    fixed = _relink(bad)
    assert fixed.verification.ok, fixed.verification.lines()
    op = fixed.operations[0]
    assert op.report["relinked"] == len(rapids.segments) and "re-linked over it" in str(op)
    # the doctored rapid's end is now reached from straight above, at the plunge feed
    at = int(np.flatnonzero(np.all(op.motion.points == low[1], axis=1))[0])
    assert op.motion.kind[at] == PLUNGE and op.motion.kind[at - 1] == RAPID
    assert np.allclose(op.motion.points[at - 1], [11.0, 11.0, fixed.safe_height])
    program = parse_gcode(programs(fixed)[0])
    cutters = {o.tool.number: Cutter(o.tool.kind, o.tool.radius) for o in fixed.operations}
    report = simulate(program, cutters, Stock(fixed.stock, 0.25))
    assert report.rapid_cut <= 1e-6, report


def test_stock_left_in_a_bore_under_the_top_is_not_a_wall_left():
    """A 3-axis tool cannot enter a bore along y under the block's top: its stock plug
    stays, its end flush with the side faces.  The part's points near the plug's centre
    (the bore's top and bottom, 4 mm away) fit a plane along the side face, steep and
    reachable; the exact nearest point, on the bore, faces down or is under the top.  The
    walls' judge settles its deepest from the exact foot: the side faces are judged, the
    plug is not (on main the plug was a wall 3.01 mm thick; on zoo's flange-xy 7.56)."""
    part = bd.Box(16, 10, 16) - bd.Rot(90, 0, 0) * bd.Cylinder(4, 12)
    job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 2.0)), sm.Finish(sm.Tool("ball", 1.5), scallop=0.05)])
    wall = _finding(job.verification, "residual on walls")
    assert job.verification.wall_points > 10_000 and wall.ok, str(job.verification)
    # the finishing moved 0.2 mm along y: the face at y = 5 beside the bore keeps 0.2
    head, tail = programs(job, "linuxcnc")[0].split("(operation: finishing")
    moved = re.sub(r"Y(-?[\d.]+)", lambda m: f"Y{float(m.group(1)) + 0.2:.4f}", tail)
    doctored = _finding(V.verify_job(job, texts=[head + "(operation: finishing" + moved]), "residual on walls")
    assert 0.15 < doctored.worst < 0.25 and abs(doctored.where[1] - 5.2) < 0.1, doctored
