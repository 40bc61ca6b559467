"""The tests' dexels along x and y (tests/stock_sim.py: ``SideDexels``, ``wall_points``,
``wall_left``, ``wall_reach``) on cases with known answers: the interval a swept tool cuts
from a line against dense tool positions; the stock a ball leaves on a 70 degree slope
between two waterline levels (the cusp ``R - sqrt(R² - (s/2)²)`` normal to the slope,
``s = dz / sin θ`` the distance between the contacts) to 1e-9 where a dexel crosses the
cusp's ridge; on a vertical wall the ball's cylindrical body clears everything above its
lowest centre (no cusp there: a cusp ``R - sqrt(R² - dz²)`` only below it); a program
with every other level left out, and one simulated with a smaller tool than it was made
for, caught by the wall measure; a post under a plate, whose walls no tool from above
reaches; a hole a hair narrower than the ball, which the height field's nodes miss and
the exact triangles catch; the distance from points to triangles against dense samples."""

from __future__ import annotations

import math

import numpy as np
import pytest
from build123d import Box, Cylinder
from stock_sim import (Cutter, SideDexels, heights_at, line_cut, parse_gcode, part_height, reach_map, side_grids,
                       surface_distance, vertex_normals, wall_left, wall_points, wall_reach)

from surfmod.cam.drop_cutter import part_triangles

R = 3.0


def prism(section, y0, y1):
    """Triangles of the prism over a convex polygon ``section`` in the (x, z) plane
    (counter-clockwise seen from -y), from y0 to y1."""
    p = np.asarray(section, float)
    a = np.column_stack([p[:, 0], np.full(len(p), y0), p[:, 1]])
    b = np.column_stack([p[:, 0], np.full(len(p), y1), p[:, 1]])
    tris = []
    for k in range(1, len(p) - 1):
        tris += [(a[0], a[k], a[k + 1]), (b[0], b[k + 1], b[k])]
    for k in range(len(p)):
        m = (k + 1) % len(p)
        tris += [(a[k], b[k], b[m]), (a[k], b[m], a[m])]
    return np.array(tris)


def box(x0, x1, y0, y1, z0, z1):
    return prism([(x0, z0), (x1, z0), (x1, z1), (x0, z1)], y0, y1)


# --- the interval one move cuts from a line --------------------------------------------------

def dense_cut(cutter, a, b, q0, z0, n=40_001):
    """Union over n tool positions of the tool's section at z0 against the line q = q0."""
    t = np.linspace(0, 1, n)
    p = a + t[:, None] * (b - a)
    u = z0 - p[:, 2]
    core, r = cutter.radius - cutter.corner, cutter.corner
    rho = np.where(u >= r, cutter.radius, core + np.sqrt(np.maximum(r * r - (r - np.clip(u, 0, r)) ** 2, 0.0)))
    rho = np.where(u >= 0, rho, -1.0)
    dq = q0 - p[:, 1]
    ok = rho >= np.abs(dq)
    if not ok.any():
        return math.inf, -math.inf
    half = np.sqrt(np.maximum(rho * rho - dq * dq, 0.0))
    return (p[:, 0] - half)[ok].min(), (p[:, 0] + half)[ok].max()


@pytest.mark.parametrize("cutter", [Cutter("flat", 1.5), Cutter("ball", 2.0), Cutter("bull", 2.0, 0.6)])
def test_line_cut_equals_dense_positions(cutter):
    rng = np.random.default_rng(7)
    n = 200
    a = rng.uniform(-2, 2, (n, 3))
    b = a + rng.uniform(-3, 3, (n, 3))
    b[::5, 2] = a[::5, 2]  # level moves
    b[::7, :2] = a[::7, :2]  # plunges
    b[::9, 1] = a[::9, 1]  # moves along the line
    q0, z0 = rng.uniform(-4, 4, n), rng.uniform(-3, 4, n)
    lo, hi = line_cut(cutter, a, b, q0, z0)
    nlo, nhi = line_cut(cutter, a, b, q0, z0, numeric=True)
    hits = 0
    for i in range(n):
        dlo, dhi = dense_cut(cutter, a[i], b[i], q0[i], z0[i])
        assert (lo[i] <= hi[i]) == (dlo <= dhi), i
        if dlo <= dhi:
            hits += 1
            # dense positions can only see less, by at most a step's worth
            assert lo[i] <= dlo + 1e-12 and hi[i] >= dhi - 1e-12
            assert dlo - lo[i] < 2e-3 and hi[i] - dhi < 2e-3
            assert abs(nlo[i] - lo[i]) < 1e-4 and abs(nhi[i] - hi[i]) < 1e-4
    assert hits > n // 4


# --- a ball's waterline levels on a slope and on a vertical wall --------------------------------

def levels_program(contacts, normal, y0, y1, radius=R):
    """Ball passes along y touching the plane at the (x, z) ``contacts``."""
    lines = ["G21 G90 G17", "T1 M6", "S8000 M3", "G0 Z60"]
    for x, z in contacts:
        cx, cz = x + radius * normal[0], z + radius * normal[2]
        lines += [f"G0 X{cx:.9f} Y{y0:.9f}", f"G1 Z{cz - radius:.9f} F500", f"G1 Y{y1:.9f}", "G0 Z60"]
    return "\n".join(lines + ["M5", "M30", ""])


THETA = math.radians(70)
N = np.array([math.sin(THETA), 0.0, math.cos(THETA)])
L, H, W = 30.0, 20.0, 20.0


def slope_part():
    """A block whose +x face leans back at 70 degrees: from (L, 0) up to (L - H cot θ, H)."""
    return prism([(0, 0), (L, 0), (L - H / math.tan(THETA), H), (0, H)], 0, W)


def cut_levels(tri, contacts, z_lines, cutter):
    stock_box = np.array([[-2.0, -5.0, 0.0], [L + 10, W + 5, H]])
    dex = SideDexels(stock_box, 0, np.array([W / 2]), np.asarray(z_lines))
    prog = parse_gcode(levels_program(contacts, N, -10, W + 10))
    a, b = np.array([m.a for m in prog.moves]), np.array([m.b for m in prog.moves])
    dex.cut(cutter, a, b)
    walls = wall_points(tri, dex)
    return walls, wall_left(dex, walls)


def slope_contacts(dz, n):
    z = 4.0 + dz * np.arange(n)
    return [(L - zz / math.tan(THETA), zz) for zz in z]


def test_ball_cusp_on_a_slope_between_levels():
    dz, n = 1.0, 6
    contacts = slope_contacts(dz, n)
    s = dz / math.sin(THETA)
    cusp = R - math.sqrt(R * R - (s / 2) ** 2)
    # the ridge between levels i and i + 1: the centres' midpoint less sqrt(R² - (s/2)²) along n
    centre_z = np.array([z for _, z in contacts]) + R * N[2]
    ridge = (centre_z[:-1] + centre_z[1:]) / 2 - math.sqrt(R * R - (s / 2) ** 2) * N[2]
    contact_z = np.array([z for _, z in contacts])
    walls, left = cut_levels(slope_part(), contacts, np.r_[ridge, contact_z], Cutter("ball", R))
    z = walls.point[:, 2]
    on_slope = walls.normal[:, 0] > 0.9
    at_ridge = on_slope & np.isin(z, ridge)
    at_contact = on_slope & np.isin(z, contact_z)
    assert at_ridge.sum() == n - 1 and at_contact.sum() == n
    np.testing.assert_allclose(left[at_ridge], cusp, atol=1e-9)
    np.testing.assert_allclose(left[at_contact], 0.0, atol=1e-9)
    # the lines between sample the cusp's profile: never above it
    zs = np.linspace(contact_z[0], contact_z[-1], 201)
    walls, left = cut_levels(slope_part(), contacts, zs, Cutter("ball", R))
    on = walls.normal[:, 0] > 0.9
    assert left[on].max() <= cusp + 1e-9 and left[on].max() > 0.9 * cusp and left[on].min() >= -1e-9


def test_every_other_level_left_out_is_caught():
    """Levels dz apart hold a scallop S on the slope; without every other one the cusp
    (``R - sqrt(R² - s²)``) is four times as high and the wall measure sees it."""
    scallop = 0.05
    s = 2 * math.sqrt(2 * R * scallop - scallop * scallop)
    dz = s * math.sin(THETA)
    contacts = slope_contacts(dz, 9)
    zs = np.linspace(contacts[0][1], contacts[-1][1], 301)
    walls, left = cut_levels(slope_part(), contacts, zs, Cutter("ball", R))
    on = walls.normal[:, 0] > 0.9
    assert scallop * 0.95 < left[on].max() <= scallop + 1e-9
    walls, left = cut_levels(slope_part(), contacts[::2], zs, Cutter("ball", R))
    worst = left[walls.normal[:, 0] > 0.9].max()
    assert worst > 3.5 * scallop and worst <= R - math.sqrt(R * R - s * s) + 1e-9


def test_smaller_tool_than_written_is_caught():
    """The program made for R simulated with R - 0.1: the smaller ball's centre sits 0.1
    lower, ``0.1 cos θ`` nearer the slope, so at least ``0.1 (1 - cos θ)`` is left
    everywhere on the levels' band (more than the program's scallop of 0.05 from R)."""
    contacts = slope_contacts(1.0, 6)
    zs = np.linspace(contacts[0][1], contacts[-1][1], 301)
    walls, left = cut_levels(slope_part(), contacts, zs, Cutter("ball", R - 0.1))
    on = walls.normal[:, 0] > 0.9
    least = 0.1 * (1 - N[2])
    assert left[on].min() >= least - 1e-9 and left[on].min() < least + 1e-3


def test_vertical_wall_is_cleared_above_the_lowest_centre():
    """On a vertical wall the ball's cylindrical body, above its centre, touches the wall
    all the way up: no cusp between levels; below the lowest centre the sphere leaves
    ``R - sqrt(R² - (z_c - z)²)``."""
    tri = box(0, L, 0, W, 0, H)
    contacts = [(L, z) for z in (6.0, 9.0, 12.0)]
    zs = np.linspace(3.2, 15.0, 60)
    stock_box = np.array([[-2.0, -5.0, 0.0], [L + 10, W + 5, H]])
    dex = SideDexels(stock_box, 0, np.array([W / 2]), zs)
    prog = parse_gcode(levels_program(contacts, np.array([1.0, 0, 0]), -10, W + 10))
    dex.cut(Cutter("ball", R), np.array([m.a for m in prog.moves]), np.array([m.b for m in prog.moves]))
    walls = wall_points(tri, dex)
    walls = walls.take(walls.normal[:, 0] > 0.99)
    left = wall_left(dex, walls)
    z = walls.point[:, 2]
    want = np.where(z >= 6.0, 0.0, R - np.sqrt(np.maximum(R * R - (6.0 - z) ** 2, 0.0)))
    assert len(z) == len(zs)
    np.testing.assert_allclose(left, want, atol=1e-9)


def test_walls_under_a_plate_are_out_of_reach():
    """A post under a wider plate: the ball cannot touch the post's walls (its body would
    cut the plate), it can touch the plate's rim; a wall nearer the stock's floor than
    its radius is out of reach of the ball too."""
    tri = np.concatenate([box(10, 20, 10, 20, 0, 8), box(4, 26, 4, 26, 8, 11)])
    stock_box = np.array([[0.0, 0.0, 0.0], [30.0, 30.0, 11.0]])
    dx, dy = side_grids(stock_box, 0.5)
    x = np.arange(0.0, 30.0001, 0.25)
    top = part_height(tri, x, x)
    floor = np.where(np.isfinite(top), top, 0.0)
    for dex in (dx, dy):
        walls = wall_points(tri, dex)
        reach = wall_reach(walls, floor, x, x, Cutter("ball", R))
        post = walls.point[:, 2] < 8
        assert post.sum() > 50 and not reach[post].any()
        rim = walls.point[:, 2] > 8
        assert reach[rim].all()


@pytest.mark.parametrize("cutter", [Cutter("flat", R), Cutter("bull", R, 1.0)])
def test_flat_and_bull_beside_a_vertical_wall(cutter):
    """One pass with the axis ``R + 0.2`` off a vertical wall, tip at z = 5: 0.2 is left
    where the full radius reaches, ``R + 0.2 - (core + sqrt(r² - (r - u)²))`` at a height
    u above the tip in a bull's corner, and the line below the tip is not cut."""
    tri = box(0, L, 0, W, 0, H)
    stock_box = np.array([[-2.0, -5.0, 0.0], [L + 10, W + 5, H]])
    zs = np.linspace(4.05, 9.05, 51)
    dex = SideDexels(stock_box, 0, np.array([W / 2]), zs)
    a, b = np.array([[L + R + 0.2, -10.0, 5.0]]), np.array([[L + R + 0.2, W + 10, 5.0]])
    dex.cut(cutter, a, b)
    walls = wall_points(tri, dex)
    walls = walls.take(walls.normal[:, 0] > 0.99)
    left = wall_left(dex, walls)
    u = walls.point[:, 2] - 5.0
    r, core = cutter.corner, cutter.radius - cutter.corner
    section = np.where(u >= r, R, core + np.sqrt(np.maximum(r * r - (r - np.clip(u, 0, r)) ** 2, 0.0)))
    want = np.where(u >= 0, R + 0.2 - section, stock_box[1, 0] - L)
    assert len(left) == len(zs)
    np.testing.assert_allclose(left, want, atol=1e-9)


def test_work_is_refused_above_its_bound():
    dx, _ = side_grids(np.array([[0.0, 0.0, 0.0], [100.0, 100.0, 50.0]]), 0.05)
    a, b = np.array([[0.0, 0.0, 0.0]]), np.array([[100.0, 100.0, 0.0]])
    with pytest.raises(ValueError, match="coarser h"):
        dx.cut(Cutter("ball", 3.0), a, b, limit=1000)


def test_surface_distance_equals_dense_samples():
    rng = np.random.default_rng(1)
    tri, pts = rng.normal(size=(20, 3, 3)), 2 * rng.normal(size=(20, 3))
    u, v = np.meshgrid(np.linspace(0, 1, 121), np.linspace(0, 1, 121))
    u, v = u[u + v <= 1], v[u + v <= 1]
    dense = (tri[:, None, 0] + u[:, None] * (tri[:, None, 1] - tri[:, None, 0])
             + v[:, None] * (tri[:, None, 2] - tri[:, None, 0])).reshape(-1, 3)
    sampled = np.array([np.linalg.norm(dense - p, axis=1).min() for p in pts])
    got = surface_distance(tri, pts, 100.0)
    # the samples lie on the triangles: never nearer than the exact, at most a sample's gap farther
    assert np.all(got <= sampled + 1e-12) and np.all(sampled - got < 0.03)
    assert np.all(np.isinf(surface_distance(tri, pts + 50.0, 1.0)))


def test_heights_at_scattered_points_equal_the_grid():
    tri = np.concatenate([box(10, 20, 10, 20, 0, 8), box(4, 26, 4, 26, 8, 11), slope_part()])
    x, y = np.linspace(-1, 31, 97), np.linspace(-2, 29, 63)
    X, Y = np.meshgrid(x, y, indexing="ij")
    np.testing.assert_array_equal(heights_at(tri, X.ravel(), Y.ravel()), part_height(tri, x, y).ravel())


@pytest.mark.parametrize("hole, fits", [(R - 0.04, False), (R + 0.1, True)])
def test_a_hole_a_hair_narrower_than_the_ball(hole, fits):
    """Walls of a through hole (stock floor 5 below the hole's top face is at -5): the quick
    map and the nodes alone let a ball of radius R into a hole of radius R - 0.04 (the
    lune it would cut lies between nodes); the exact triangles on the tool's circle do not.
    A hole of R + 0.1 takes it down to its floor's reach (centre no lower than -2)."""
    tri, deflection, (_, owner) = part_triangles((Box(20, 20, 10) - Cylinder(hole, 10)).wrapped, 0.002,
                                                 face_index=True)
    stock_box = np.array([[-10.0, -10.0, -5.0], [10.0, 10.0, 5.0]])
    walls = wall_points(tri, side_grids(stock_box, 0.25)[0], normals=vertex_normals(tri, owner))
    radial = -walls.point[:, :2] / np.hypot(walls.point[:, 0], walls.point[:, 1])[:, None]
    inner = (np.hypot(walls.point[:, 0], walls.point[:, 1]) < hole + 0.01) & (walls.point[:, 2] > -1.9)
    # the face's normal, not the facet's: radial within the mesh's own tilt
    assert np.abs(walls.normal[inner, :2] - radial[inner]).max() < 2e-3
    walls = walls.take(inner)
    x = np.arange(-10, 10.0001, 0.25)
    top = part_height(tri, x, x)
    floor = np.where(np.isfinite(top), top, -5.0)
    ball = Cutter("ball", R)
    slack = deflection + 1e-6
    quick = wall_reach(walls, floor, x, x, ball, slack=slack, quick=reach_map(floor, 0.25, ball, slack=slack))
    exact = wall_reach(walls, floor, x, x, ball, slack=slack, triangles=tri)
    assert len(walls) > 100
    assert quick.all()  # a first sieve: never refuses what the tool reaches
    assert exact.all() == fits and exact.any() == fits
