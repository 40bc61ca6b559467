"""G2/G3 arcs in the posts: circular runs of a path found from the points alone
(surfmod/cam/arcs.py), written as arc words, read back by LinuxCNC's interpreter
(``rs274``) as ``ARC_FEED`` and traced on the same points as the polyline: every vertex
on the traced path within the fit tolerance plus the 4-decimal rounding, every point of
an arc within the sagitta bound of the polyline; a helix entry of a job cut the same in
the independent stock simulation with arcs as with straight moves."""

from __future__ import annotations

import re

import build123d as bd
import numpy as np
import pytest
from scipy import ndimage
from canon_paths import arc_points, canonical, off_path, polyline_distance
from stock_sim import RS274, Cutter, Stock, parse_canon, run_rs274, simulate

import surfmod as sm
from surfmod.cam.arcs import MAX_SAGITTA, TOLERANCE, find_arcs
from surfmod.cam.job import Job, Operation
from surfmod.cam.post import programs
from surfmod.cam.roughing import FEED, PLUNGE, RAPID, Motion

needs_rs274 = pytest.mark.skipif(RS274 is None, reason="rs274 (Debian package linuxcnc-uspace) is not installed")
ROUNDING = 1e-4  # the programs' 4 decimals (x, y to nearest, z up, centres to nearest)


def circle(c, r, a0, a1, n, z0=0.0, z1=None):
    t = np.linspace(0, 1, n + 1)
    a = a0 + (a1 - a0) * t
    z = z0 + ((z0 if z1 is None else z1) - z0) * t
    return np.column_stack([c[0] + r * np.cos(a), c[1] + r * np.sin(a), z])


# --- the fitter on known shapes -----------------------------------------------------------------

def test_circle_and_helix_are_found_with_direction_and_centre():
    ccw = circle((3, -2), 10.0, 0.0, np.pi, 200)
    arcs = find_arcs(ccw)
    assert [(a.start, a.end, a.ccw) for a in arcs] == [(0, 200, True)]
    assert np.allclose(arcs[0].centre, (3, -2), atol=1e-9) and abs(arcs[0].radius - 10) < 1e-9
    # a clockwise helix of three turns: half turns (the most one word sweeps), sharing end points
    cw = circle((0, 0), 4.0, 0.0, -6 * np.pi, 288, 5.0, 2.0)
    arcs = find_arcs(cw)
    assert len(arcs) == 6 and not any(a.ccw for a in arcs)
    assert arcs[0].start == 0 and arcs[-1].end == 288
    assert all(a.end == b.start for a, b in zip(arcs, arcs[1:]))


@pytest.mark.parametrize("case", ["polygon", "line", "noisy", "coarse", "z_dips", "kinds"])
def test_shapes_that_are_not_arcs(case):
    kind = None
    if case == "polygon":  # corners on a circle, 45 degree steps: a polygon
        pts = circle((0, 0), 5.0, 0, 2 * np.pi, 8)
    elif case == "line":
        pts = np.column_stack([np.linspace(0, 10, 30), np.linspace(0, 3, 30), np.zeros(30)])
    elif case == "noisy":  # points off the circle by up to 10 x the tolerance
        pts = circle((0, 0), 5.0, 0, np.pi, 100)
        pts[:, :2] *= 1 + 1e-3 / 5 * np.sin(np.arange(101) * 1.7)[:, None]
    elif case == "coarse":  # on the circle, but the chords stand 0.02 mm off it
        pts = circle((0, 0), 20.0, 0, np.pi / 2, 18)
        assert 20 * (1 - np.cos(np.pi / 72)) > MAX_SAGITTA
    elif case == "z_dips":  # a helix whose middle point dips below the line of its heights
        pts = circle((0, 0), 5.0, 0, np.pi / 2, 40, 1.0, 0.0)
        pts[::2, 2] += 5 * TOLERANCE  # the others lie below the arc between them
    else:  # a rapid in the middle of a circle splits it
        pts = circle((0, 0), 5.0, 0, np.pi / 2, 8)
        kind = np.full(9, FEED)
        kind[4] = RAPID
    assert [(a.start, a.end) for a in find_arcs(pts, kind)] == []


def test_point_off_the_circle_splits_the_arc():
    pts = circle((0, 0), 5.0, 0, np.pi, 120)
    pts[60, :2] *= 1 + 3 * TOLERANCE / 5
    arcs = find_arcs(pts)
    assert arcs and all(not (a.start < 60 < a.end) for a in arcs)
    # every point an arc covers lies on its circle
    for a in arcs:
        p = pts[a.start:a.end + 1, :2]
        assert np.abs(np.hypot(*(p - a.centre).T) - a.radius).max() <= TOLERANCE


# --- a synthetic operation through both posts and rs274 ---------------------------------------

def synthetic_job():
    """Rapid in, a level semicircle (CCW), a clockwise descending helix, a straight run, a
    noisy ring (straight moves), a square; every kind of run the fitter must judge."""
    pieces, kinds = [[[10, 0, 20], [10, 0, 1]]], [[RAPID, RAPID]]
    def add(p, k):
        pieces.append(p)
        kinds.append([k] * len(p))
    add([[10, 0, 0]], PLUNGE)
    add(circle((0, 0), 10.0, 0, np.pi, 180)[1:], FEED)
    add(circle((-6, 0), 4.0, np.pi, -3 * np.pi, 192, 0.0, -2.0)[1:], PLUNGE)
    add(np.column_stack([np.linspace(-10, 20, 31), np.zeros(31), np.full(31, -2.0)])[1:], FEED)
    ring = circle((20, 10), 10.0, -np.pi / 2, 1.5 * np.pi, 240, -2.0)
    ring[:, :2] += 3e-3 * np.column_stack([np.sin(np.arange(241) * 2.3), np.cos(np.arange(241) * 1.1)])
    add(ring[1:], FEED)
    add([[30, 0, -2], [30, 20, -2], [10, 20, -2], [10, 0, -2]], FEED)
    add([[10, 0, 20]], RAPID)
    motion = Motion(np.vstack(pieces).astype(float), np.concatenate(kinds).astype(np.int8))
    tool = sm.Tool("flat", 3.0).with_defaults(1)
    op = Operation("roughing", tool, motion, 60.0)
    return Job(None, np.array([[-12.0, -12.0, -5.0], [32.0, 22.0, 0.0]]), (op,), 20.0)


def test_synthetic_program_arcs_are_the_circles():
    job = synthetic_job()
    text = programs(job)[0]
    words = re.findall(r"^(G[0-3]) ", text, flags=re.M)
    # the semicircle is one G3, the helix's two turns four half turns of G2; nothing else
    assert words.count("G3") == 1 and words.count("G2") == 4
    g2 = [ln for ln in text.splitlines() if ln.startswith("G2 ")]
    assert all(" Z" in ln for ln in g2) and g2[-1].startswith("G2 X-10.0000 Y0.0000 Z-2.0000")
    plain = programs(job, arcs=False)[0]
    assert not re.search(r"^G[23] ", plain, flags=re.M)
    assert len(plain.splitlines()) - len(text.splitlines()) == 180 + 192 - 5


def _pass(c, r, a0, a1, n, z, safe):
    """A feed arc entered and left as the finishing does: rapid over its start, down, cut,
    up at the feed, rapid to the clearance height."""
    ring = circle(c, r, a0, a1, n, z)
    x, y = ring[0, :2]
    pts = [[x, y, safe], [x, y, z + 1.0], ring, [[*ring[-1, :2], z + 1.0]], [[*ring[-1, :2], safe]]]
    kinds = [[RAPID], [RAPID], np.full(len(ring), FEED), [FEED], [RAPID]]
    return np.vstack(pts), np.concatenate(kinds).astype(np.int8)


def test_an_extended_operation_keeps_its_written_head(monkeypatch):
    """A finishing with a repair's passes appended writes its first motion's lines from
    the written ones and only the passes afresh: the program equals the one written from
    scratch, on passes whose arcs end at the join, and falls back to writing it all where
    the join is an arc's middle (a circle cut in two)."""
    import surfmod.cam.post as post_module

    tool = sm.Tool("ball", 3.0).with_defaults(2)
    stock = np.array([[-30.0, -30.0, -5.0], [30.0, 30.0, 0.0]])
    rng = np.random.default_rng(11)
    head = [_pass(rng.uniform(-9, 9, 2), rng.uniform(3, 12), a, a + rng.uniform(1, 3), 40, -rng.uniform(0, 4), 20.0)
            for a in rng.uniform(0, 6, 5)]
    tail = [_pass(rng.uniform(-9, 9, 2), rng.uniform(3, 12), a, a - rng.uniform(1, 3), 40, -rng.uniform(0, 4), 20.0)
            for a in rng.uniform(0, 6, 4)]
    ring = circle((0, 0), 8.0, 0.0, 3.0, 60, -1.0)
    cases = [(np.vstack([p for p, _ in head]), np.concatenate([k for _, k in head]),
              np.vstack([p for p, _ in tail]), np.concatenate([k for _, k in tail]), True),
             (ring[:31], np.full(31, FEED, np.int8), ring[31:], np.full(30, FEED, np.int8), False)]
    for p0, k0, p1, k1, joins in cases:
        first = Operation("finishing", tool, Motion(p0, k0), 60.0)
        whole = Operation("finishing", tool, Motion(np.vstack([p0, p1]), np.concatenate([k0, k1])), 60.0,
                          extends=first)
        monkeypatch.setattr(post_module, "_WRITTEN", {})
        programs(Job(None, stock, (first,), 20.0))
        assert post_module._joins(first, whole) is joins
        kept = programs(Job(None, stock, (whole,), 20.0))[0]
        monkeypatch.setattr(post_module, "_WRITTEN", {})
        assert kept == programs(Job(None, stock, (whole,), 20.0))[0]
        assert re.search(r"^G[23] ", kept, flags=re.M)


@needs_rs274
@pytest.mark.parametrize("post", ["linuxcnc", "grbl"])
def test_rs274_traces_the_polyline(tmp_path, post):
    job = synthetic_job()
    path = tmp_path / "arcs.ngc"
    path.write_text(programs(job, post)[0])
    text = run_rs274(path, tmp_path / "arcs.txt")
    ends, arcs = canonical(text)
    assert text.count("ARC_FEED") == 5 == len(arcs)
    pts = job.operations[0].motion.points
    # every vertex of the verified polyline lies on the traced path
    d = off_path(pts, ends, arcs)
    assert d.max() <= TOLERANCE + 2 * ROUNDING, d.max()
    # every point of each arc lies within the sagitta bound of the polyline
    along = np.vstack([arc_points(a, 200) for a in arcs])
    gap = polyline_distance(along, pts)
    assert gap.max() <= MAX_SAGITTA + TOLERANCE + 2 * ROUNDING, gap.max()
    # and the arcs' sagitta is what they had: the helix (r = 4, 96 points a turn) stands off
    # its chords by r (1 - cos(pi / 96)); the semicircle (r = 10, 180 points) by less
    assert gap.max() == pytest.approx(4 * (1 - np.cos(np.pi / 96)), abs=3 * ROUNDING)


# --- a job's helix entry: the same cut in the stock simulation ---------------------------------

@pytest.fixture(scope="module")
def bull_job(tmp_path_factory):
    part = bd.Box(24, 16, 6) - bd.Pos(3, 0, 2) * bd.Box(10, 8, 3)
    path = tmp_path_factory.mktemp("arcs") / "pocket.step"
    bd.export_step(part, str(path))
    return sm.machine(str(path), 0.5, [sm.Finish(sm.Tool("bull", 2.0, 0.5), stepover=1.5)])


@needs_rs274
def test_helix_entry_is_arcs_and_cuts_as_the_polyline(bull_job, tmp_path):
    """The bull's helix entry becomes G3 words; the stock the simulation leaves after the
    entry written with arcs equals the one after it written as straight moves within the
    sagitta bound (plus the simulation's own chords of the arcs, 1e-3 inside them)."""
    tool = bull_job.operations[0].tool
    entries = []
    for arcs in (True, False):
        text = programs(bull_job, arcs=arcs)[0]
        # the program up to its first move at the cutting feed: the entry
        cut = text.index(f" F{tool.feed:g}\n")
        entries.append(text[:text.rindex("\n", 0, cut)] + "\nM5\nM30\n")
    n_arcs = len(re.findall(r"^G3 ", entries[0], flags=re.M))
    assert n_arcs >= 2 and not re.search(r"^G[23] ", entries[1], flags=re.M)
    tops = []
    for name, text in zip(("arcs", "lines"), entries):
        p = tmp_path / f"{name}.ngc"
        p.write_text(text)
        canon = run_rs274(p, tmp_path / f"{name}.txt")
        assert canon.count("ARC_FEED") == (n_arcs if name == "arcs" else 0)
        stock = Stock(bull_job.stock, 0.25)
        rep = simulate(parse_canon(canon, arc_chord=1e-3), {1: Cutter("bull", 2.0, 0.5)}, stock)
        assert rep.rapid_cut <= 1e-9 and rep.cutting_moves > 10
        tops.append(stock.top)
    lo, hi = bull_job.stock
    # the entry went down into the stock (the finishing's raster first: onto the block's
    # top, under 0.5 of stock)
    assert lo[2] < tops[0].min() < hi[2] - 0.25
    bound = MAX_SAGITTA + 1e-3 + 2 * ROUNDING
    diff = np.abs(tops[0] - tops[1])
    # nodes at exactly the tool's radius from an end point lie on its vertical side: a
    # rounding there decides whether it is cut; beside them (one cell) the stocks agree
    assert np.mean(diff > bound) < 0.005, np.mean(diff > bound)
    lo_n, hi_n = ndimage.minimum_filter(tops[1], 3), ndimage.maximum_filter(tops[1], 3)
    assert np.all((tops[0] >= lo_n - bound) & (tops[0] <= hi_n + bound))
