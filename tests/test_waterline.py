"""Waterline contours (surfmod/cam/waterline.py): exact offsets of a plate, a tilted
plate and a pyramid for flat, ball and bull ends (textbook distances), loops closed and
oriented, the work bounded, bad input refused; then OpenCAMLib's ``Waterline`` on a
corpus part: every point OCL puts on its loops lies on ours within 1e-6 of the part's
size (OCL's weave leaves rare spikes off the contour; those are shown to be off it by
OCL's own drop-cutter)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from ocl_reference import drop as ocl_drop
from ocl_reference import needs_opencamlib
from ocl_reference import polyline_distance
from ocl_reference import waterline as ocl_waterline

from surfmod.cam.cutters import cutter
from surfmod.cam.drop_cutter import TriangleGrid, drop, triangle_rows
from surfmod.cam.fiber_contact import pair_intervals
from surfmod.cam.waterline import ContourPoints, _Fibers, fiber_pairs, pit_lines, waterline
from surfmod.errors import SurfmodError

CORPUS_PART = "trimesh_featuretype.STEP"


def tool(kind, R, r=0.0):
    return cutter(kind, R, r)


def radius_at(kind, R, r, h):
    """Textbook radius of the tool's profile at height h above the tip."""
    if kind == "flat" or h >= (R if kind == "ball" else r):
        return R
    if kind == "ball":
        return math.sqrt(R * R - (R - h) ** 2)
    return R - r + math.sqrt(r * r - (r - h) ** 2)


def square(size=10.0, z=0.0):
    s = size
    return np.array([[[0, 0, z], [s, 0, z], [s, s, z]], [[0, 0, z], [s, s, z], [0, s, z]]], float)


def box_distance(xy, lo, hi):
    dx = np.maximum(np.maximum(lo[0] - xy[:, 0], xy[:, 0] - hi[0]), 0)
    dy = np.maximum(np.maximum(lo[1] - xy[:, 1], xy[:, 1] - hi[1]), 0)
    return np.hypot(dx, dy)


def signed_area(loop):
    x, y = loop[:, 0], loop[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


@pytest.mark.parametrize("kind, R, r", [("flat", 1.0, 0.0), ("ball", 1.0, 0.0), ("bull", 1.5, 0.5)])
@pytest.mark.parametrize("h", [0.05, 0.2, 0.45, 2.0])
def test_plate_offset_is_the_profile_radius(kind, R, r, h):
    """A level square plate h above the tip: the contour is the square grown by the
    tool's radius at height h, corners rounded, counter-clockwise."""
    (loop,), = waterline(square(), tool(kind, R, r), [-h])
    rho = radius_at(kind, R, r, h)
    d = box_distance(loop[:, :2], (0, 0), (10, 10))
    assert np.abs(d - rho).max() < 1e-12
    assert np.all(loop[:, 2] == -h)
    # the rounded square's area, up to the chords' shortfall on the corner arcs
    exact = 100 + 40 * rho + math.pi * rho * rho
    assert signed_area(loop[:, :2]) == pytest.approx(exact, rel=1e-5)
    assert signed_area(loop[:, :2]) < exact


def test_plate_above_the_tool_is_not_seen_and_below_it_is_the_shank():
    """Above the plate's height nothing is cut; far below it the shank (radius R) meets it."""
    assert waterline(square(), tool("ball", 1.0), [0.1]) == [[]]
    (loop,), = waterline(square(), tool("ball", 1.0), [-50.0])
    assert np.abs(box_distance(loop[:, :2], (0, 0), (10, 10)) - 1.0).max() < 1e-12


@pytest.mark.parametrize("kind, R, r", [("flat", 2.0, 0.0), ("ball", 2.0, 0.0), ("bull", 2.0, 0.7)])
def test_tilted_plate_facet_contact(kind, R, r):
    """A plane z = s·x (slope s, unit normal n): on the downhill side (x < 0 edge far away)
    the contour is where the tool's support point along -n touches the plane: the line
    x = x*(z) from the textbook contact of each profile."""
    s = 0.5
    big = 40.0
    tri = np.array([[[-big, -big, -s * big], [big, -big, s * big], [big, big, s * big]],
                    [[-big, -big, -s * big], [big, big, s * big], [-big, big, -s * big]]])
    z = 0.0
    (loop,), = waterline(tri, tool(kind, R, r), [z], sampling=0.5)
    n = np.array([-s, 0.0, 1.0]) / math.hypot(s, 1.0)
    # tip at (x, 0, z); support point along -n: ball: centre - R n; flat: rim uphill; bull: both
    if kind == "ball":
        off = np.array([0.0, 0.0, R]) - R * n
    elif kind == "flat":
        off = np.array([R, 0.0, 0.0])
    else:
        off = np.array([R - r, 0.0, r]) - r * n
    # the support point on the plane: z + off_z = s (x + off_x)
    x_star = (z + off[2]) / s - off[0]
    mid = np.abs(loop[:, 1]) < big / 2
    left = loop[mid & (loop[:, 0] < 0), 0] if x_star < 0 else loop[mid & (loop[:, 0] < big / 2), 0]
    assert np.abs(left - x_star).min() < 1e-9
    assert np.abs(left - x_star).max() < 1e-9


def test_pyramid_edge_contact_ball():
    """A square pyramid (apex up): at a tip height the ball's contour on a diagonal lies at
    the textbook distance from the edge line (sphere centre at R from the edge)."""
    a, top = 10.0, 8.0
    base = np.array([[-a, -a, 0], [a, -a, 0], [a, a, 0], [-a, a, 0]], float)
    apex = np.array([0.0, 0.0, top])
    tri = np.array([[base[k], base[(k + 1) % 4], apex] for k in range(4)])
    R, z = 1.5, 3.0
    (loop,), = waterline(tri, tool("ball", R), [z], sampling=0.4, tolerance=1e-9)
    # on the diagonal direction u = (1, 1)/√2, the ball's centre (t u, z + R) at distance R
    # from the edge line apex -> base corner (a, a, 0)
    e = np.array([a, a, -top]) / np.linalg.norm([a, a, -top])
    u = np.array([1.0, 1.0]) / math.sqrt(2)
    along = loop[:, :2] @ u
    across = loop[:, :2] @ np.array([-u[1], u[0]])
    k = np.argmin(np.abs(across) + (along < 0) * 1e9)
    t = along[k]
    c = np.array([t * u[0], t * u[1], z + R]) - apex
    dist = np.linalg.norm(c - (c @ e) * e)
    assert abs(across[k]) < 0.05 and dist == pytest.approx(R, abs=1e-7)


def test_loops_are_closed_oriented_and_nested():
    """A frame (a square ring): an outer loop counter-clockwise round the material and an
    inner loop clockwise (the material on the left of travel), both at the textbook offset."""
    outer, inner = square(20.0), square(10.0)
    inner[..., :2] += 5
    # the ring as 8 triangles between the two squares
    o = np.array([[0, 0], [20, 0], [20, 20], [0, 20]], float)
    i = o / 2 + 5
    tri = []
    for k in range(4):
        a, b, c, d = o[k], o[(k + 1) % 4], i[(k + 1) % 4], i[k]
        tri += [[[*a, 0], [*b, 0], [*c, 0]], [[*a, 0], [*c, 0], [*d, 0]]]
    loops, = waterline(np.array(tri, float), tool("flat", 1.0), [0.0], sampling=0.3)
    assert len(loops) == 2
    areas = sorted(signed_area(lp[:, :2]) for lp in loops)
    assert areas[0] == pytest.approx(-(8 * 8), abs=1e-6)  # the hole shrunk by R: square corners, met to the tolerance
    assert areas[1] == pytest.approx(400 + 80 + math.pi, rel=1e-5)


def box_walls(x0, y0, x1, y1, top):
    """The four walls (from z = 0) and the lid of an axis-aligned box: 10 triangles."""
    c = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    tri = []
    for p, q in zip(c, np.roll(c, -1, axis=0)):
        tri += [[[*p, 0], [*q, 0], [*q, top]], [[*p, 0], [*q, top], [*p, top]]]
    return tri + [[[x0, y0, top], [x1, y0, top], [x1, y1, top]], [[x0, y0, top], [x1, y1, top], [x0, y1, top]]]


@pytest.mark.parametrize("R, h", [(0.7, 0.35), (1.1, 0.55), (1.3, 0.35)])
def test_rows_along_a_wall_give_the_exact_contour(R, h):
    """Issue 36: a fiber can run along a straight wall's offset (a pit's fiber did on
    trimesh_featuretype), and a rounding then puts a node outside for the row and inside
    for the column through it; the column's crossing was taken at the middle of its
    edge, half a spacing into the material, deeper than the refinement looks (the
    finishing lifted a piece 2.36 mm there).  A comb of ten teeth whose ends' offsets lie on
    the grid's rows (which start at the part's low y less R and two spacings): every loop
    point lies at R from the boxes (before: up to h / 2 off)."""
    rows = np.arange(-R - 2 * h, 20, h)
    rects = [(0.0, 0.0, 31.0, 2.0)] + [(3.0 * i + 1, 0.0, 3.0 * i + 2.5, rows[np.searchsorted(rows, 3 + 0.7 * i)] - R)
                                       for i in range(10)]
    tri = np.array([t for r in rects for t in box_walls(*r, 5.0)], float)
    loops, = waterline(tri, tool("flat", R), [1.0], sampling=h)
    assert len(loops) >= 1
    for lp in loops:
        d = np.min([box_distance(lp[:, :2], r[:2], r[2:]) for r in rects], axis=0)
        assert np.abs(d - R).max() < 1e-9


def pyramid_and_shelf() -> np.ndarray:
    """A square pyramid 20 wide and 8 high and, beside it, a shelf at z = 6 whose band
    joins the pyramid's offset at the low levels."""
    a, top = 10.0, 8.0
    base = np.array([[-a, -a, 0], [a, -a, 0], [a, a, 0], [-a, a, 0]], float)
    tri = [[base[k], base[(k + 1) % 4], [0.0, 0.0, top]] for k in range(4)]
    shelf = square(6.0, z=6.0)
    shelf[..., 0] += a + 0.5
    return np.concatenate([np.array(tri), shelf])


@pytest.mark.parametrize("kind, R, r", [("ball", 1.5, 0.0), ("bull", 1.5, 0.5), ("flat", 1.5, 0.0)])
def test_levels_together_equal_levels_alone(kind, R, r):
    """Several levels in one call (unsorted) give each level's loops of a call of its own:
    the triangles wholly above a level's corner height, met once and carried down the
    levels, forbid what they forbid when met at that level.  A pyramid and, beside it, a
    shelf at z = 6 whose band joins the pyramid's offset at the low levels."""
    tri = pyramid_and_shelf()
    levels = [1.0, 5.5, 3.0, 0.2, 6.2]
    together = waterline(tri, tool(kind, R, r), levels, sampling=0.4)
    for z, loops in zip(levels, together):
        (alone,) = waterline(tri, tool(kind, R, r), [z], sampling=0.4)
        assert len(loops) == len(alone) >= 1
        assert (max(lp[:, 0].max() for lp in loops) > 16.5) == (z < 6.0)  # the shelf's band
        for p, q in zip(loops, alone):
            assert p.shape == q.shape and np.abs(p - q).max() < 1e-12


def test_bad_input_and_bounds():
    with pytest.raises(SurfmodError, match="tool"):
        waterline(square(), tool("drill", 1.0), [0.0])
    with pytest.raises(SurfmodError, match="radius"):
        waterline(square(), tool("ball", 0.0), [0.0])
    with pytest.raises(SurfmodError, match="corner"):
        waterline(square(), tool("bull", 1.0, 1.0), [0.0])
    with pytest.raises(SurfmodError, match="part"):
        waterline(np.zeros((3, 3)), tool("ball", 1.0), [0.0])
    with pytest.raises(SurfmodError, match="z_levels"):
        waterline(square(), tool("ball", 1.0), [np.nan])
    with pytest.raises(SurfmodError, match="sampling"):
        waterline(square(), tool("ball", 1.0), [0.0], sampling=-1)
    with pytest.raises(SurfmodError, match="sampling"):  # the work estimate refuses before starting
        waterline(square(1000.0), tool("ball", 1.0), np.zeros(50), sampling=1e-3)


@pytest.mark.parametrize("kind, R, r", [("ball", 1.5, 1.5), ("flat", 1.5, 0.0), ("bull", 1.5, 0.6)])
def test_the_pair_estimate_counts_the_pairs_met(kind, R, r):
    """Issue 36: the fibers meet the triangles through an index by height and grid line,
    and ``fiber_pairs`` counts what that meets before the work starts.  A pyramid with
    a shelf over 40 levels: the estimate is an upper bound within 1.5x of the grid pairs
    met.  Levels wholly below the part cost the first's pairs once, not once per level
    (the old count, triangles x lines x levels, was 40x for them)."""
    tri = pyramid_and_shelf()
    # refine the pyramid's faces so the index has triangles to skip: 4 x 64 + the shelf
    for _ in range(3):
        m = [(t[0] + t[1]) / 2 for t in tri], [(t[1] + t[2]) / 2 for t in tri], [(t[2] + t[0]) / 2 for t in tri]
        tri = np.concatenate([np.stack([tri[:, 0], m[0], m[2]], 1), np.stack([m[0], tri[:, 1], m[1]], 1),
                              np.stack([m[2], m[1], tri[:, 2]], 1), np.stack([m[0], m[1], m[2]], 1)])
    cut = tool(kind, R, r)
    levels = np.linspace(0.1, 7.9, 40)
    _, fib = waterline(tri, cut, levels, sampling=0.4, fibers=True)
    estimate = fiber_pairs(tri, R, 0.4, levels, cut.corner)
    assert fib.pairs <= estimate <= 1.5 * fib.pairs, (fib.pairs, estimate)
    below = np.linspace(-5.0, -1.0 - r, 40)
    _, one = waterline(tri, cut, below[:1], sampling=0.4, fibers=True)
    _, many = waterline(tri, cut, below, sampling=0.4, fibers=True)
    assert many.pairs == one.pairs > 0
    assert fiber_pairs(tri, R, 0.4, below, cut.corner) == fiber_pairs(tri, R, 0.4, below[:1], cut.corner)


def intervals(tri, ox, oy, dx, dy, z, shape):
    """``(t0, t1)`` per pair: where ``shape`` pushed along the pair's fiber ``o + t d`` at
    tip height ``z`` meets the pair's triangle ``tri`` ``(P, 3, 3)``."""
    return pair_intervals(triangle_rows(tri), np.arange(len(tri)), ox, oy, dx, dy, z, shape)


@pytest.mark.parametrize("kind, R, r", [("ball", 1.5, 1.5), ("flat", 1.5, 0.0), ("bull", 1.5, 0.6)])
def test_fiber_intervals_are_where_the_dropped_tool_reaches_z(kind, R, r):
    """Per (fiber, triangle) pair the interval is exactly where the tool at tip height z
    meets the triangle, i.e. where the drop-cutter (an independent solver: its bull edge is
    a bisection on the height's derivative, the waterline's an ellipse offset) stops at or
    above z: along the fiber the dropped tip is above z inside the interval and below
    outside, up to the ends.  Random triangles, some with a level edge, each placed
    in its own 20 mm cell so that one grid drops on all of them."""
    rng = np.random.default_rng(11)
    side = 40
    n = side * side
    tri = rng.random((n, 3, 3)) * 6 - 3
    tri[: n // 4, 1, 2] = tri[: n // 4, 0, 2]
    cell = 20.0 * np.column_stack([np.arange(n) % side, np.arange(n) // side])
    tri[:, :, :2] += cell[:, None, :]
    ang = rng.random(n) * 2 * np.pi
    d = np.column_stack([np.cos(ang), np.sin(ang)])
    o = cell + rng.random((n, 2)) * 6 - 3 - 5 * d
    z = -0.5
    t0, t1 = intervals(tri, o[:, 0], o[:, 1], d[:, 0], d[:, 1], z, cutter(kind, R, r))
    grid = TriangleGrid(tri, R)
    hit = t0 <= t1
    assert 0.3 < hit.mean() < 0.9
    # just inside each end the dropped tip is at or above z, just outside at or below it
    # (a shank-bounded end is a jump, a profile-bounded one a square-root slope)
    step = 1e-9
    for t, inward in ((t0[hit], 1.0), (t1[hit], -1.0)):
        h_in = drop(grid, cutter(kind, R, r), o[hit] + (t + inward * step)[:, None] * d[hit])
        h_out = np.nan_to_num(drop(grid, cutter(kind, R, r), o[hit] + (t - inward * step)[:, None] * d[hit]),
                              nan=-np.inf)
        assert h_in.min() > z - 1e-4 and h_out.max() < z + 1e-4
    ts = np.linspace(-1.0, 11.0, 49)
    h = drop(grid, cutter(kind, R, r), (o[:, None, :] + ts[None, :, None] * d[:, None, :]).reshape(-1, 2))
    h = np.nan_to_num(h, nan=-np.inf).reshape(n, len(ts))
    inside = (ts[None, :] >= t0[:, None]) & (ts[None, :] <= t1[:, None])
    assert not np.any(inside & (h < z - 1e-9))
    assert not np.any(~inside & (h > z + 1e-9))


@pytest.mark.parametrize("kind, R, r", [("ball", 1.5, 0.0), ("bull", 1.5, 0.6)])
def test_fiber_query_meets_what_every_triangle_meets(kind, R, r):
    """The refinement's fibers (short segments ``o ± reach d``) take their triangles from
    the grid's lists in one compiled walk: the intervals found are exactly those of every
    triangle in the soup met by brute force (pair_intervals on all of them, clipped to the
    fiber), a fiber at a time.  Random triangles at random heights, fibers of random
    length and direction over them, two levels."""
    rng = np.random.default_rng(5)
    n = 3000
    centre = rng.random((n, 3)) * [60, 60, 8]
    tri = centre[:, None, :] + rng.random((n, 3, 3)) * 3 - 1.5
    fib = _Fibers(tri, cutter(kind, R, r), 4.0)
    f = 400
    o = rng.random((f, 2)) * 60
    ang = rng.random(f) * 2 * np.pi
    d = np.column_stack([np.cos(ang), np.sin(ang)])
    reach = rng.uniform(0.05, 4.0, f)
    for z in (2.0, 6.0):
        qi, lo, hi = fib.query(o, d, z, reach)
        got = {(int(q), round(float(a), 9), round(float(b), 9)) for q, a, b in zip(qi, lo, hi)
               if a <= reach[q] and b >= -reach[q]}
        want = set()
        for q in range(f):
            t0, t1 = intervals(tri, np.full(n, o[q, 0]), np.full(n, o[q, 1]), np.full(n, d[q, 0]),
                               np.full(n, d[q, 1]), z, cutter(kind, R, r))
            on = (t0 <= t1) & (t0 <= reach[q]) & (t1 >= -reach[q])
            want |= {(q, round(float(a), 9), round(float(b), 9)) for a, b in zip(t0[on], t1[on])}
        assert len(want) > 200 and got == want


@pytest.mark.parametrize("kind, R, r", [("ball", 3.0, 3.0), ("bull", 3.0, 1.0), ("flat", 3.0, 0.0)])
def test_short_fibers_on_a_wall_meet_the_triangles_the_tool_can_reach(kind, R, r):
    """Issue 36: a refinement fiber meets only the triangles the tool at its level can
    touch: those whose box comes within the tool's radius at their top (the ball's end is
    narrow low on a wall), not every triangle within R.  Fibers 0.1 mm long across the
    contour of a 60-degree slope meshed in 0.25 mm squares meet at most 2.5x the pairs
    that have an interval on them (the boxes grown by R: 9.1x for the ball, 6.3x for the
    bull, 5x for the flat end), and the intervals are those of every triangle."""
    u = np.linspace(0, 20, 81)
    X, Y = np.meshgrid(u, u, indexing="ij")
    P = np.stack([X, Y, math.tan(math.radians(60)) * X], -1)
    a, b, c, d = P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]
    tri = np.concatenate([np.stack([a, b, c], 2).reshape(-1, 3, 3), np.stack([a, c, d], 2).reshape(-1, 3, 3)])
    cut, z = tool(kind, R, r), 15.0
    (loop,), = waterline(tri, cut, [z], sampling=1.0)
    o = loop[(loop[:, 1] > 5) & (loop[:, 1] < 15), :2]
    across = np.tile([[1.0, 0.0]], (len(o), 1))
    fib = _Fibers(tri, cut, 1.5)
    qi, lo, hi = fib.query(o, across, z, np.full(len(o), 0.05))
    on = (lo <= 0.05) & (hi >= -0.05)
    assert len(o) > 10 and on.sum() >= len(o) and fib.refined <= 2.5 * on.sum(), (fib.refined, on.sum())
    for q in range(len(o)):
        t0, t1 = intervals(tri, np.full(len(tri), o[q, 0]), np.full(len(tri), o[q, 1]), np.ones(len(tri)),
                           np.zeros(len(tri)), z, cut)
        want = (t0 <= t1) & (t0 <= 0.05) & (t1 >= -0.05)
        assert np.array_equal(np.sort(lo[on & (qi == q)]), np.sort(t0[want])), q


# --- OpenCAMLib ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def corpus_triangles(corpus_dir):
    from surfmod.cam.drop_cutter import part_triangles
    from surfmod.inputs import to_shape

    tri, _ = part_triangles(to_shape(corpus_dir / CORPUS_PART), 0.05)
    return tri


def test_pit_fibers_cross_the_holes_and_run_along_no_wall(corpus_triangles):
    """Issue 36: trimesh_featuretype's eight Ø6.74 holes leave a ball of radius 3 pits
    narrower than the spacing 1.5; a fiber in x and one in y cross each.  Windows
    balanced by the walls of a pocket a few cells wide were once moved onto one wall's
    tool positions (16 fibers more, each along a wall's offset, where a rounding decides
    on which side of the contour a node lies) and mirrored pits gave fibers a rounding
    apart: every fiber now lies at least 1e-6 from the offset of every wall facing
    across it, and from the next fiber."""
    tri, R = corpus_triangles, 3.0
    lines = pit_lines(tri, R, 1.5)
    for axis, holes in ((0, [-57.0738, -28.4988, 0.0762, 28.6512]), (1, [-25.4, 25.4])):
        assert np.abs(lines[axis][:, None] - holes).min(axis=0).max() < 1e-6
        assert np.diff(lines[axis]).min() > 1e-6
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n = n / np.linalg.norm(n, axis=1)[:, None]
    for axis in (0, 1):
        wall = np.abs(n[:, axis]) > 1 - 1e-9  # a vertical wall facing along the axis
        offset = tri[wall, :, axis].mean(axis=1) + R * np.sign(n[wall, axis])
        assert np.abs(lines[axis][:, None] - offset).min() > 1e-6


@needs_opencamlib
@pytest.mark.parametrize("kind, R, r", [("ball", 3.0, 0.0), ("flat", 3.0, 0.0), ("bull", 3.0, 1.0)])
def test_equals_opencamlib_waterline(tmp_path, corpus_triangles, kind, R, r):
    tri = corpus_triangles
    pts = tri.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    size = float((hi - lo).max())
    z = float(lo[2] + 0.4 * (hi[2] - lo[2]))
    sampling = 0.5
    (ours,) = waterline(tri, tool(kind, R, r), [z], sampling=sampling)
    theirs, _ = ocl_waterline(tmp_path, tri, kind, R, r, z, sampling)
    real = [lp for lp in theirs if len(lp) >= 3]
    # each of OCL's loops lies along one of ours and each of ours has one of OCL's along it
    # (OCL sometimes returns one loop in pieces: on trimesh_featuretype's outer loop, two
    # pieces 6 and 33 mm apart along a straight stretch, so the counts alone differ)
    owner = [{int(np.argmin([polyline_distance(p[None], [lp])[0] for lp in ours])) for p in piece}
             for piece in real]
    assert all(len(o) == 1 for o in owner), owner
    assert set().union(*owner) == set(range(len(ours))) and len(ours) <= len(real)
    for lp in ours:
        assert len(lp) >= 3 and np.all(lp[:, 2] == z)
    pts_ocl = np.vstack(theirs)
    d = polyline_distance(pts_ocl, ours)
    off = d > 1e-6 * size
    assert off.mean() < 0.01, f"{off.sum()} of {len(d)} OCL points off our contour"
    if off.any():
        # OCL's stray points are not on the contour: its own drop-cutter finds the tool
        # clear of the part (tip able to go below z) at and round each of them
        ring = pts_ocl[off, None, :2] + 0.2 * sampling * np.array(
            [[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]])[None]
        heights, _ = ocl_drop(tmp_path, tri, kind, R, r, ring.reshape(-1, 2), float(lo[2]) - 100)
        assert np.all(heights < z - 1e-3)


@needs_opencamlib
@pytest.mark.parametrize("kind, R, r", [("ball", 3.0, 0.0), ("flat", 3.0, 0.0), ("bull", 3.0, 1.0)])
def test_drop_cutter_equals_opencamlib(tmp_path, corpus_triangles, kind, R, r):
    """surfmod.cam's drop-cutter heights (the waterline's companion for the tool's other
    direction) equal OCL's BatchDropCutter on the same triangles, ball, flat and bull."""
    tri = corpus_triangles
    pts = tri.reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    xy = lo[:2] + np.random.default_rng(3).random((2000, 2)) * (hi - lo)[:2]
    ours = drop(TriangleGrid(tri, R), cutter(kind, R, r), xy)
    floor = float(lo[2]) - 100.0
    theirs, _ = ocl_drop(tmp_path, tri, kind, R, r, xy, floor)
    miss = np.isnan(ours)
    assert miss.mean() < 0.2 and np.all(theirs[miss] == floor)
    assert np.abs(theirs[~miss] - ours[~miss]).max() < 1e-8 * float((hi - lo).max())


def test_contour_points_on_the_waterline_fibers_split_as_their_own():
    """Finishing splits its gouging chords on the fibers its waterline built (one grid of
    the part, not two): the points are those of contour points built afresh, bit for bit,
    chords across the loops of a pyramid with a shelf, ball and bull."""
    tri = pyramid_and_shelf()
    for cut in (tool("ball", 1.5), tool("bull", 1.5, 0.5)):
        (loops,), fibers = waterline(tri, cut, [2.0], sampling=0.4, fibers=True)
        shared, own = ContourPoints(tri, cut, 0.6, fibers), ContourPoints(tri, cut, 0.6)
        assert shared.fib is fibers and own.fib is not fibers
        for loop in loops:
            pts = loop[::5, :2]
            which = np.arange(len(pts) - 1)
            assert np.array_equal(shared.split(2.0, pts, which), own.split(2.0, pts, which))
