"""Finishing in sm.machine: waterline contours on steep regions beside the raster, the
scallop measured normal to the surface by the independent stock simulation
(tests/stock_sim.py, through LinuxCNC's interpreter), and the rest the tool cannot reach
reported on parts with known answers."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import build123d as bd
import numpy as np
import pytest
from stock_sim import RS274, Cutter, Stock, normal_residual, parse_canon, part_height, reachable, run_rs274, simulate

import surfmod as sm
from surfmod.cam import waterline as waterline_module
from surfmod.cam.drop_cutter import TriangleGrid, drop
from surfmod.cam.finishing import judge_links, recut, summary_lines
from surfmod.cam.roughing import FEED, PLUNGE, RAPID, Moves
from surfmod.cam.toolpath import meshed_part
from surfmod.errors import SurfmodError

SAMPLES = Path(__file__).resolve().parent.parent / "step_samples"
needs_rs274 = pytest.mark.skipif(RS274 is None, reason="rs274 (Debian package linuxcnc-uspace) is not installed")

# the dome: a hemisphere of radius RS on a plate, every slope from 0 to 90 degrees
RS, BALL, SCALLOP = 6.0, 2.0, 0.1


def dome():
    return bd.Pos(0, 0, -1) * bd.Box(18, 18, 2) + (bd.Sphere(RS) & bd.Pos(0, 0, RS / 2) * bd.Box(15, 15, RS))


@pytest.fixture(scope="module")
def dome_job():
    return sm.machine(dome(), 0.5, [sm.Finish(sm.Tool("ball", BALL), scallop=SCALLOP)])


def test_dome_report_and_links(dome_job):
    fin = dome_job.operations[0]
    rep = fin.report
    wl = rep["waterline"]
    # levels from the top of the steep band down to the plate; spaced for the scallop at
    # 45 degrees and more (the sphere's slopes there: sin θ_min of the band)
    s = 2 * math.sqrt(2 * BALL * (SCALLOP - rep["raster"]["margin"]) - (SCALLOP - rep["raster"]["margin"]) ** 2)
    assert wl["levels"] >= RS * (1 - math.cos(math.radians(45))) / s
    assert wl["z_spacing"][1] <= s + 1e-9 and wl["contours"] > 0 and wl["length"] > 0
    # passes over the dome's flanks closer (cross slopes up to 45 degrees), over the plate s apart
    assert rep["raster"]["least_stepover"] <= s * math.cos(math.radians(44)) + 1e-9
    assert s * 0.99 <= rep["raster"]["stepover"] <= s + 1e-9
    lines = summary_lines(rep)
    assert any(line.startswith("waterline on slopes >= 45") for line in lines)
    assert any(line.startswith("raster:") for line in lines)
    # the plate meets the sphere at a right angle: the ball leaves a ring there, reported
    rest = rep["rest"]
    assert rest["regions"] == 1 and rest["max_depth"] > 0.5
    (x0, y0), (x1, y1) = rest["box"]
    assert abs(x0 + RS) < BALL and abs(x1 - RS) < BALL and abs(y0 + RS) < BALL and abs(y1 - RS) < BALL
    # rapids across only at the clearance height, never between contours
    p, kind = fin.motion.points, fin.motion.kind
    seg = np.diff(p, axis=0)
    across = (kind[1:] == RAPID) & (np.hypot(seg[:, 0], seg[:, 1]) > 1e-9)
    assert np.all(np.abs(p[1:][across, 2] - dome_job.safe_height) < 1e-9)
    assert np.all(np.abs(p[:-1][across, 2] - dome_job.safe_height) < 1e-9)
    assert set(np.unique(kind)) <= {RAPID, FEED, PLUNGE}


@needs_rs274
def test_dome_scallop_normal_to_the_surface(dome_job, tmp_path):
    """The program through rs274 and the stock simulation over a quarter of the dome:
    no gouge of the exact sphere and plate, no rapid through stock, and the stock left
    stands at most the scallop (plus the tolerance) above the sphere along its normal
    wherever the ball can reach, on the steep band as on the flat top and the plate."""
    path = tmp_path / "dome.ngc"
    sm.export_gcode(dome_job, path, post="linuxcnc")
    prog = parse_canon(run_rs274(path, tmp_path / "dome.txt"))
    h = 0.04
    lo, hi = dome_job.stock
    stock = Stock([(-0.5, -0.5, lo[2]), (RS + 3.0, RS + 3.0, hi[2])], h, origin=(0.0, 0.0))
    X, Y = stock.nodes()
    r2 = X * X + Y * Y
    exact = np.where(r2 < RS * RS, np.sqrt(np.maximum(RS * RS - r2, 0.0)), 0.0)
    cutter = Cutter("ball", BALL)
    rep = simulate(prog, {1: cutter}, stock, exact)
    tol = dome_job.operations[0].report["tolerance"]
    # measured vertically (the mesh's deflection would be 1/cos θ deep on a slope of angle θ:
    # the finishing tool keeps it from the mesh in every direction)
    print(rep)
    assert rep.gouge < tol + 1e-4, str(rep)
    assert rep.rapid_cut <= 1e-9 and rep.rapid_part < 0 and rep.cut_without_spindle == 0, str(rep)
    surface = reachable(exact, cutter, h)
    reach = surface - exact < 1e-3  # the ring the ball cannot reach at the dome's foot is rest
    radial = np.sqrt(r2 + stock.top ** 2) - RS  # the stock's distance to the sphere
    on_sphere = reach & (r2 < (RS * math.sin(math.radians(80))) ** 2)
    steep = on_sphere & (r2 > (RS * math.sin(math.radians(45))) ** 2)
    flat_top = on_sphere & (r2 < (RS * math.sin(math.radians(20))) ** 2)
    plate = reach & (r2 > (RS + BALL + 0.5) ** 2)
    bound = SCALLOP + tol
    for name, sel, res in (("steep band", steep, radial), ("dome top", flat_top, radial),
                           ("plate", plate, stock.top - exact)):
        r = res[sel]
        print(f"{name}: residual max {r.max():.4f}, 99% {np.percentile(r, 99):.4f} over {sel.sum()} nodes")
        assert sel.sum() > 500 and r.max() <= bound, name
        assert r.min() > -tol - 1e-4, name  # no gouge normal to the surface
    # the same measure the brief names: vertical residual x cos(slope) over the reachable surface
    res = normal_residual(stock.top, surface, h)
    r = res[reach & np.isfinite(res) & (r2 < (RS * math.sin(math.radians(80))) ** 2)]
    assert r.max() <= bound + 5e-3


def slot_block(w=2.0, length=20.0, depth=4.0):
    """A 30 x 20 x 10 block (top z = 5) with a closed slot w wide, ``length`` long, ``depth`` deep."""
    return bd.Box(30, 20, 10) - bd.Pos(0, 0, 5 - depth / 2) * bd.Box(length, w, depth)


def test_rest_in_a_narrow_slot_is_reported():
    """A ball of diameter 3.2 cannot enter a slot 2 wide: the whole slot is rest, its
    depth the opening of the slot by the ball (closed form) above the floor."""
    R, w, L, depth = 1.6, 2.0, 20.0, 4.0
    job = sm.machine(slot_block(w, L, depth), 0.0, [sm.Finish(sm.Tool("ball", R), scallop=0.05, steep_angle=None)])
    rest = job.operations[0].report["rest"]
    h = rest["spacing"]
    assert h == pytest.approx(R / 8)
    assert rest["regions"] == 1
    # the slot's area, up to the grid: nodes strictly inside it
    assert abs(rest["area"] - w * L) <= h * (w + L) + 1e-9
    (x0, y0), (x1, y1) = rest["box"]
    assert max(abs(x0 + L / 2), abs(x1 - L / 2), abs(y0 + w / 2), abs(y1 - w / 2)) <= h + 1e-9
    # across the slot's middle: the ball resting on the slot's edges (centre at p across the
    # slot, on the nearer edge) covers the node y at 5 + sqrt(R² - (w/2 - |p|)²) - sqrt(R² - (y - p)²)
    xs, ys, left = rest["map"]
    i = int(np.argmin(np.abs(xs)))
    assert abs(xs[i]) < 1e-9
    inside = np.flatnonzero(np.abs(ys) < w / 2 - 1e-9)
    p = np.linspace(-w / 2, w / 2, 200_001)
    for j in inside:
        y = ys[j]
        ok = np.abs(y - p) <= R
        opening = (5 + np.sqrt(R * R - (w / 2 - np.abs(p[ok])) ** 2) - np.sqrt(R * R - (y - p[ok]) ** 2)).min()
        expect = opening - (5 - depth)
        # the grid holds fewer tool positions than the continuum: its opening lies above, by
        # less than the slope times the grid spacing
        assert expect - 1e-6 <= left[i, j] <= expect + 0.05, y
    assert rest["max_depth"] >= left[i, inside].max() and rest["max_depth"] <= depth + 1e-9
    assert any("rest not reached" in line and "1 region" in line for line in summary_lines(job.operations[0].report))


def test_no_rest_on_open_ground():
    """A plain block: the ball reaches all of its top (nothing to report)."""
    job = sm.machine(bd.Box(20, 10, 4), 0.0, [sm.Finish(sm.Tool("ball", 1.5), scallop=0.05)])
    rep = job.operations[0].report
    assert rep["rest"]["box"] is None and rep["rest"]["area"] == 0.0
    assert any(line.startswith("rest: the tool reaches everywhere") for line in summary_lines(rep))


def test_steep_angle_is_checked():
    with pytest.raises(sm.SurfmodError, match="^steep_angle"):
        sm.machine(bd.Box(20, 10, 4), 0.0, [sm.Finish(sm.Tool("ball", 1.5), scallop=0.05, steep_angle=0.0)])


# --- cam_part: roughing and finishing, the scallop normal to the reachable surface --------------

@needs_rs274
@pytest.mark.corpus
def test_cam_part_job_scallop_in_stock(tmp_path):
    """``sm.machine`` on step_samples/cam_part.step (rough flat r=5, finish ball r=3,
    scallop 0.05) through rs274 and the stock simulation: no gouge beyond the tolerance, no
    rapid through stock, and the residual normal to the reachable surface at most the
    scallop plus the tolerance over the whole top (issue 26 measured 0.059 for the raster
    alone); the vertical walls are cut by the contours (their steep pieces) down to the part's bottom."""
    from surfmod.inputs import to_shape
    from surfmod.cam.drop_cutter import part_triangles

    S = 0.05
    job = sm.machine(SAMPLES / "cam_part.step", 3.0, [sm.Rough(sm.Tool("flat", 5.0), stepdown=3.0, allowance=0.3),
                                                      sm.Finish(sm.Tool("ball", 3.0, flute_length=30.0), scallop=S)])
    fin = job.operations[1]
    wl = fin.report["waterline"]
    assert wl["levels"] > 20 and wl["bottom"] == pytest.approx(job.stock[0, 2], abs=1e-6)
    path = tmp_path / "cam_job.ngc"
    sm.export_gcode(job, path, post="linuxcnc")
    prog = parse_canon(run_rs274(path, tmp_path / "cam_job.txt"))
    tri, deflection = part_triangles(to_shape(SAMPLES / "cam_part.step"), 0.001)
    h = 0.1
    stock = Stock(job.stock, h)
    top = part_height(tri, stock.x, stock.y)
    rep = simulate(prog, {1: Cutter("flat", 5.0), 2: Cutter("ball", 3.0)}, stock, top)
    tol = fin.report["tolerance"]
    assert rep.gouge < tol + deflection + 1e-4, str(rep)
    assert rep.rapid_cut <= 1e-9 and rep.rapid_part < 0 and rep.cut_without_spindle == 0, str(rep)
    surface = reachable(top, Cutter("ball", 3.0), h)
    res = normal_residual(stock.top, surface, h)
    inner = np.isfinite(res) & np.isfinite(top)
    r = res[inner]
    print(f"cam_part job: residual normal to the reachable surface max {r.max():.4f}, "
          f"99.5% {np.percentile(r, 99.5):.4f}, share above {S}: {np.mean(r > S):.3%}")
    assert r.max() <= S + tol
    # beside the walls (outside the part) no stock is left above the part's bottom + the ball's reach
    X, Y = stock.nodes()
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    beside = ~np.isfinite(top) & (np.maximum(np.maximum(lo[0] - X, X - hi[0]), np.maximum(lo[1] - Y, Y - hi[1])) > 0.2)
    assert stock.top[beside].max() <= job.stock[0, 2] + 3.0 + 1e-6


def test_waterline_chord_across_a_notch_is_split_not_lifted():
    """A 20 mm box with a nub 0.01 mm proud of its +x wall (0.02 wide, z 8-10): below it
    the ball's (r = 3) waterline bulges 0.01 outward over 0.5 mm, placed a quarter of the
    way along one of the fiber grid's 1.5 mm chords (the grid's rows at -1.0079 + 1.5 k),
    so the chord's middle lies on the wall's contour and its refinement misses the bulge;
    the drop-cutter check finds the chord cutting down to the nub (before issue 26's fix
    those moves were lifted, by up to 7.18 mm).  Now they are split at exact contour
    points: nothing lifted, and no move below the nub comes nearer its footprint than the
    radius (sampled every 0.01 mm).  Runs in about 0.5 s."""
    R, p, yc = 3.0, 0.01, 0.117
    body = bd.Box(20, 20, 10, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
    job = sm.machine(body + bd.Pos(10 + p / 2, yc, 9) * bd.Box(p, 0.02, 2), 1.0,
                     [sm.Finish(sm.Tool("ball", R), scallop=0.15)])
    rep = job.operations[0].report
    assert rep["waterline"]["split"] > 0  # the notch is there: pieces had chords cutting into it
    assert any(f"{rep['waterline']['split']} chords split at the contour" in line for line in summary_lines(rep))
    assert rep["lifted"] <= rep["tolerance"], rep["lifted"]
    pts = job.operations[0].moves
    a, b = pts[:-1], pts[1:]
    low = (a[:, 2] < 8) & (b[:, 2] < 8)
    a, b = a[low], b[low]
    n = np.ceil(np.linalg.norm(b - a, axis=1) / 0.01).astype(int) + 1
    owner = np.repeat(np.arange(len(a)), n)
    t = (np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)) / np.repeat(n, n)
    q = a[owner] + t[:, None] * (b[owner] - a[owner])
    dx = np.maximum(np.maximum(10 - q[:, 0], q[:, 0] - (10 + p)), 0)
    dy = np.maximum(np.abs(q[:, 1] - yc) - 0.01, 0)
    near = np.hypot(dx, dy)
    assert low.sum() > 100 and near.min() >= R - rep["tolerance"], near.min()


@pytest.mark.corpus
def test_featuretype_waterline_follows_notches_instead_of_lifting(corpus_dir):
    """On trimesh_featuretype some waterline chords (1.5 mm, the fiber grid's) have their
    middle on the contour of a wall while a small feature near the top of the wall pushes
    the contour across the chord between: the drop-cutter check finds the chord cutting
    down to the feature's top (22.4 mm deep at z = 0, 27 pieces over 1 mm).  Such chords
    are split at exact contour points until they follow it, so nothing is lifted (before:
    ``lifted`` 22.44 mm), the moves still judged against the drop-cutter heights.  A pit's
    fiber along a wall's offset once put a grid crossing half a spacing into the material,
    which no split settles (``lifted`` 2.36 mm at z 31.4)."""
    job = sm.machine(corpus_dir / "trimesh_featuretype.STEP", 2.0,
                     [sm.Finish(sm.Tool("ball", 3.0, flute_length=80), scallop=0.15)])
    rep = job.operations[0].report
    wl = rep["waterline"]
    assert wl["split"] > 0  # the notches are there: pieces had gouging chords
    assert rep["lifted"] <= rep["tolerance"] and wl["lifted"] <= rep["tolerance"], rep["lifted"]
    assert rep["gouge"] + rep["deflection"] <= rep["tolerance"]


def test_a_big_part_spreads_the_waterline_fibers_to_fit_the_cap(monkeypatch):
    """Issue 36: a metre-size part was refused with "choose a coarser sampling", an option
    `surfmod machine` does not have.  Where fibers half a radius apart over all levels
    would pass the waterline's cap, the finishing spreads them (up to a radius) and says
    so; where even a radius does not fit, it refuses naming the scallop, which the
    command has.  The cap is lowered here so that a small part meets it."""
    part = bd.Box(20, 20, 5) + bd.Pos(0, 0, 4) * bd.Cylinder(5, 3)
    tool = sm.Tool("ball", 1.0)
    seen, count = [], waterline_module.fiber_pairs

    def spy(tri, radius, sampling, levels, corner, pits=None):  # what the finishing counts with
        seen.append((tri, radius, levels, corner))
        return count(tri, radius, sampling, levels, corner, pits)

    monkeypatch.setattr(waterline_module, "fiber_pairs", spy)
    free = sm.machine(part, 1.0, [sm.Finish(tool, scallop=0.05)], verify=False).operations[0].report["waterline"]
    assert "sampling" not in free
    tri, radius, tri_levels, corner = seen[0]
    # a cap between what fibers half a radius and a radius apart need
    cap = math.sqrt(count(tri, radius, tool.radius / 2, tri_levels, corner)
                    * count(tri, radius, tool.radius, tri_levels, corner))
    monkeypatch.setattr(waterline_module, "MAX_PAIRS", cap)
    job = sm.machine(part, 1.0, [sm.Finish(tool, scallop=0.05)], verify=False)
    w = job.operations[0].report["waterline"]
    assert tool.radius / 2 < w["sampling"] <= tool.radius and w["levels"] == len(tri_levels)
    assert any("spread from half the tool radius" in line for line in summary_lines(job.operations[0].report))
    monkeypatch.setattr(waterline_module, "MAX_PAIRS", 10)
    with pytest.raises(SurfmodError, match=r"^scallop: the waterline's \d+ levels .* choose a larger scallop"):
        sm.machine(part, 1.0, [sm.Finish(tool, scallop=0.05)], verify=False)


def test_a_clear_part_drops_the_tool_grown_by_the_deflection():
    """``meshed_part(..., clear=True)`` (the finishing's mesh) drops the cutter grown by the
    mesh's deflection and lifts every height by it, on a grid built once for the grown
    radius: its heights are those of a grid built for the grown tool from the plain
    part's triangles, bit for bit."""
    part = bd.Box(20, 20, 5) + bd.Pos(0, 0, 2.5) * bd.Sphere(6)
    cutter = sm.Tool("ball", 2.0).cutter
    plain, clear = meshed_part(part, cutter, 0.01), meshed_part(part, cutter, 0.01, clear=True)
    d = clear.deflection
    assert d == plain.deflection and clear.lift == d and clear.cutter == cutter.grown(d)
    assert clear.grid.radius == cutter.radius + d
    xy = np.random.default_rng(3).uniform(-12, 12, (500, 2))
    grown = drop(TriangleGrid(plain.grid.triangles, cutter.radius + d), cutter.grown(d), xy) + d
    assert np.array_equal(clear.height(xy), grown, equal_nan=True)


def test_cross_passes_stand_closer_the_further_the_residual_was_over():
    """A repair over a region left ``over`` times its bound runs its cross passes closer by
    the square root (a cusp on concave ground grows as the square of the spacing), at most
    four times closer: over a plate with a hole a ball dips into, 1, 4 and 100 times over
    give passes a 0.71, 0.35 and 0.18 stepover apart."""
    part = bd.Box(40, 40, 5) - bd.Cylinder(1.5, 6)
    tool = sm.Tool("ball", 5.2).with_defaults(2)
    mesh = meshed_part(part, tool.cutter, 0.005, clear=True)
    stock = np.array([[-22.0, -22.0, -2.5], [22.0, 22.0, 4.5]])
    xs = []
    for over in (1.0, 4.0, 100.0):
        motion, passes = recut(mesh, tool, [(-2.0, -2.0, 2.0, 2.0)], stepover=1.0, direction="x", tolerance=0.005,
                               stock=stock, safe=10.0, rest=None, over=over)
        feed = motion.points[1:][motion.kind[1:] == FEED]
        xs.append(np.unique(np.round(feed[:, 0], 6)))
    gaps = [float(np.median(np.diff(x))) for x in xs]
    asked = np.array([1.0, 0.5, 0.25]) * math.sqrt(0.5)  # the passes spread evenly over the box: no wider
    assert np.all((asked * 0.95 < gaps) & (gaps <= asked + 1e-9)), gaps


def test_links_are_judged_and_the_contours_judged_as_made_are_not_again():
    """Issue 36: the contours' pieces are gouge-checked as they are made; the finishing's
    last verdict judges the links, entries and retracts between them, not the pieces'
    moves again (that took 5 of the 280 mm mould's 140 s).  A bump 1 high at x 5: a
    judged piece of 100 moves over flat ground costs no drop but the move into it; a link
    across the bump is found and named by its place in the sequence; the depth reported
    is the deepest of both."""
    seen = []

    def height(xy):
        seen.append(len(xy))
        return np.where(np.abs(xy[:, 0] - 5.0) < 0.3, 1.0, 0.0)

    part = SimpleNamespace(height=height)
    out = Moves()
    out.add([[0.0, 0.0, 2.0], [0.0, 0.0, 0.0]], PLUNGE)
    out.add(np.column_stack([np.linspace(0.01, 1.0, 100), np.zeros(100), np.zeros(100)]), FEED, -0.25)
    out.add([[1.0, 0.0, 2.0]], RAPID)
    depth = judge_links(part, out, 0.01, "finishing")
    assert sum(seen) == 3 * (3 + 2) and depth.max() == 0.0  # 3 moves: down, into the piece, up
    out.add([[1.0, 0.0, 0.0], [9.0, 0.0, 0.0]], FEED)  # down, then across the bump
    with pytest.raises(SurfmodError, match="finishing move 104 cuts 1 deep"):
        judge_links(part, out, 0.01, "finishing")
    again = Moves()
    again.add([[0.0, 0.0, 1.0]], FEED)
    again.add([[1.0, 0.0, 1.0], [2.0, 0.0, 1.0]], FEED, 0.005)
    assert judge_links(part, again, 0.01, "finishing").max() == 0.005
