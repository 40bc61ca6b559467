"""How deep a finishing tool goes: its flutes, then a shank no wider than its end down a
hole, until the holder would stand on the part (issue 36).

The part is a 24 x 14 x 12 block (top z = 12) with two blind holes of radius 1.7, a
little wider than the ball (r = 1.5): the tool's pit in each is 0.4 mm wide, narrower
than the waterline's fibers.  The tool has 4 mm of flutes, 4 mm of shank as wide as the
ball and the default holder (radius 3.75, wider than the holes).  Hole A is 7 deep: deeper
than the flutes, within flutes + shank, so the ball reaches its floor.  Hole B is 10 deep:
below z 4 the holder would stand on the block's top, so the tool stops there.

The judge is the written program read back by the tests' own G-code reader
(:mod:`stock_sim`) and textbook geometry on the cylinders: the ball at tip height ``L``
on a contour of radius ``rho`` round the hole's axis reaches the wall at height ``w`` out
to ``rho + sqrt(r² - (w - L - r)²)`` (its flutes' cylinder ``rho + r`` above its equator);
the wall keeps ``RH`` less the farthest any contour reaches.  The finishing stopped its
contours at the part's top less the flutes (z 8) and its fibers missed the pits, and so
left both holes' walls uncut below z 8.
"""

import math

import build123d as bd
import numpy as np
import pytest
from stock_sim import parse_gcode

import surfmod as sm

TOP, RH, R, FLUTE, SHANK, SCALLOP = 12.0, 1.7, 1.5, 4.0, 4.0, 0.05
HOLES = {"A": (-6.0, 7.0), "B": (6.0, 10.0)}  # x of the axis (y = 0), depth


def block():
    part = bd.Pos(0, 0, TOP / 2) * bd.Box(24, 14, TOP)
    for x, depth in HOLES.values():
        part -= bd.Pos(x, 0, TOP - depth / 2) * bd.Cylinder(RH, depth)
    return part


@pytest.fixture(scope="module")
def machined(tmp_path_factory):
    tool = sm.Tool("ball", R, flute_length=FLUTE, shank_length=SHANK)
    job = sm.machine(block(), 0.0, [sm.Finish(tool, scallop=SCALLOP)])
    path = tmp_path_factory.mktemp("hole_depth") / "job.ngc"
    sm.export_gcode(job, path)
    return job, parse_gcode(path.read_text())


def contours(prog, x0):
    """The program's full circles in the hole at ``x0``: ``(tip height, least radius)``
    of every level whose feed moves inside the tool's pit go all round the axis."""
    pts = np.array([m.b for m in prog.moves if not m.rapid])
    rho = np.hypot(pts[:, 0] - x0, pts[:, 1])
    inside = pts[rho < RH - R + 0.05]
    out = []
    for z in np.unique(np.round(inside[:, 2], 4)):
        ring = inside[np.abs(inside[:, 2] - z) < 1e-4]
        ang = np.sort(np.arctan2(ring[:, 1], ring[:, 0] - x0))
        if len(ring) >= 8 and np.diff(np.r_[ang, ang[0] + 2 * math.pi]).max() < math.pi / 4:
            out.append((float(z), float(np.hypot(ring[:, 0] - x0, ring[:, 1]).min())))
    return out


def wall_left(levels, heights):
    """Stock left on the hole's wall at ``heights`` after the contours ``levels``."""
    reach = np.full(len(heights), -np.inf)
    for tip, rho in levels:
        a = heights - (tip + R)
        ball = np.where(np.abs(a) <= R, rho + np.sqrt(np.maximum(R * R - a * a, 0.0)), -np.inf)
        reach = np.maximum(reach, np.where(a > 0, rho + R, ball))
    return RH - reach


def test_a_shank_as_wide_as_the_ball_follows_it_down_a_hole(machined):
    job, prog = machined
    tol = job.operations[0].report["tolerance"]
    levels = contours(prog, HOLES["A"][0])
    floor = TOP - HOLES["A"][1]
    assert floor < TOP - FLUTE  # deeper than the flutes
    assert levels and abs(min(t for t, _ in levels) - floor) < 0.01  # the ball's tip on the hole's floor
    assert all(rho <= RH - R + tol + 1e-3 for _, rho in levels)  # no cut into the wall
    # the whole wall above the ball's corner fillet holds the scallop
    left = wall_left(levels, np.linspace(floor + R, TOP, 2000))
    assert left.max() <= SCALLOP + tol, left.max()
    assert job.verification.ok, str(job.verification)


def test_the_holder_stops_the_tool_above_a_deeper_hole(machined):
    job, prog = machined
    op = job.operations[0]
    tol = op.report["tolerance"]
    # the holder (wider than either hole) at every written move, 20 points along each,
    # stands no lower than the block's top wherever it overlaps the block
    holder = op.tool.holder_radius
    for m in prog.moves:
        p = np.asarray(m.a) + np.linspace(0, 1, 20)[:, None] * (np.asarray(m.b) - np.asarray(m.a))
        over = (np.abs(p[:, 0]) < 12 + holder) & (np.abs(p[:, 1]) < 7 + holder)
        assert np.all(p[over, 2] + FLUTE + SHANK >= TOP - 1e-3), (m.a, m.b)
    # it reaches down to there (the job holds the holder a cusp, scallop + tolerance, above
    # the stock its model cannot see): the wall holds the scallop above the ball's equator
    # at the holder's limit, and below it the moves left out are reported
    lowest = TOP - FLUTE - SHANK
    levels = contours(prog, HOLES["B"][0])
    assert levels and min(t for t, _ in levels) < lowest + SCALLOP + tol + 0.05
    left = wall_left(levels, np.linspace(lowest + R, TOP, 2000))
    assert left.max() <= SCALLOP + tol, left.max()
    held = op.report["holder"]
    assert held is not None and abs(held.deepest[0] - HOLES["B"][0]) < RH
    assert job.verification.ok, str(job.verification)
