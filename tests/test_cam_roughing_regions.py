"""Roughing clears every region it can enter and reports the ones it cannot (issue 26).

A block with a slot just wider than the tool grown by the allowance (the tool may stand
only on a strip 0.8 mm wide along its middle), a pocket round an island, and a round hole
0.1 mm wider than the grown tool in radius (its centre on a node of the roughing's grid,
cell = stepover / 3 = 0.5 mm): the tool could stand there only within 0.1 mm of the
hole's axis, where no ramp of at most 15° and no helix fits (a ring of 0.63 mm round,
12 turns at 15° descend 2 mm; the level drops 2.8 mm) — known answer: left, reported.

The program is read back as the controller reads it (rs274 when installed, else the
G-code text) and run through the independent stock simulation (tests/stock_sim.py):
no gouge, no rapid through stock, no steep descent of the flat end into material, and
after roughing no stock above allowance + stepdown over what the tool can reach except
in the reported hole, whose measured area is at most the reported one.
"""

from __future__ import annotations

import build123d as bd
import numpy as np
import pytest
from stock_sim import Cutter, Program, Stock, part_height, read_back, simulate
from test_cam_job_proof import rough_rest

import surfmod as sm
from surfmod.cam.roughing import MAX_RAMP_ANGLE, RAPID
from surfmod.cam.drop_cutter import part_triangles

R, A, STEPDOWN, STEPOVER, MARGIN, CELL = 2.0, 0.3, 4.0, 1.5, 2.0, 0.1
HOLE = (10.0, 8.0)


def block():
    part = bd.Box(40, 30, 8)  # z from -4 to 4
    slot = bd.Pos(-10, 8.7, 1.5) * bd.Box(12, 2 * (R + A) + 0.8, 5)  # floor z = -1
    pocket = bd.Pos(-2, -7, 2) * bd.Box(20, 10, 4)  # floor z = 0
    island = bd.Pos(-2, -7, 1) * bd.Cylinder(2.0, 2)  # top z = 2
    hole = bd.Pos(*HOLE, 1) * bd.Cylinder(R + A + 0.1, 6)  # floor z = -2
    return part - slot - pocket - hole + island


def rough_and_sweep(shape, rough: sm.Rough, margin: float, cell: float, folder):
    """``sm.machine`` of ``rough`` alone, its LinuxCNC program read back and swept through
    the tests' stock (``cell``): ``(job, stock, part top, simulation report, mesh
    deflection, part triangles)``."""
    job = sm.machine(shape, margin, [rough])
    ngc = folder / "rough.ngc"
    sm.export_gcode(job, ngc, post="linuxcnc")
    prog = read_back(ngc, arc_chord=1e-4)
    tri, deflection = part_triangles(shape, 0.01)
    stock = Stock(job.stock, cell)
    top = part_height(tri, stock.x, stock.y)
    rep = simulate(Program([m for m in prog.moves if m.tool == 1]), {1: Cutter("flat", rough.tool.radius)}, stock, top)
    return job, stock, top, rep, deflection, tri


@pytest.fixture(scope="module")
def roughed(tmp_path_factory):
    rough = sm.Rough(sm.Tool("flat", R, flute_length=30), stepdown=STEPDOWN, allowance=A, stepover=STEPOVER)
    return rough_and_sweep(block(), rough, MARGIN, CELL, tmp_path_factory.mktemp("regions"))


def test_the_hole_is_reported_left(roughed):
    job, *_ = roughed
    left = job.operations[0].report["left"]
    assert len(left) == 1
    (g,) = left
    assert np.hypot(g["centre"][0] - HOLE[0], g["centre"][1] - HOLE[1]) < 0.1
    # from the top face's level (part top + allowance) down to the last level the hole is open at
    assert g["top"] == pytest.approx(4 + A, abs=1e-6) and g["z"] < g["top"] - 1
    assert np.pi * R * R <= g["area"] <= np.pi * (R + 1) ** 2
    text = str(job)
    assert "left uncut" in text and "at (10.0, 8.0)" in text


def test_no_gouge_no_rapid_through_stock(roughed):
    _, _, _, rep, deflection, _ = roughed
    assert rep.gouge <= -A + deflection + 1e-4, str(rep)
    assert rep.rapid_cut <= 1e-9 and rep.rapid_part < 0 and rep.cut_without_spindle == 0, str(rep)


def test_entries_ramp_never_plunge(roughed):
    job, *_ = roughed
    op = job.operations[0]
    p, kind = op.motion.points, op.motion.kind
    seg = np.diff(p, axis=0)
    cut = (kind[1:] != RAPID) & (seg[:, 2] < -1e-6) & (p[1:, 2] < job.stock[1, 2])
    slope = -seg[cut, 2] / np.maximum(np.hypot(seg[cut, 0], seg[cut, 1]), 1e-300)
    assert cut.sum() > 10 and np.all(slope <= np.tan(np.radians(MAX_RAMP_ANGLE)) + 1e-9)
    # rapids go down only outside the stock or onto the level above an entry
    down = (kind[1:] == RAPID) & (seg[:, 2] < -1e-9)
    inside = np.all((p[1:, :2] > job.stock[0, :2] - R) & (p[1:, :2] < job.stock[1, :2] + R), axis=1)
    assert np.all(p[1:][down & inside, 2] >= job.operations[0].report["levels"][-1])


def test_every_other_region_is_cleared(roughed):
    job, stock, top, _, _, tri = roughed
    rest = rough_rest(stock, top, job.operations[0], CELL, tri)
    assert rest["share"] == 0, rest["share"]
    # the hole is the one place left: material over its floor, inside the reported area
    assert 0 < rest["left_area"] <= rest["declared_area"]
    X, Y = stock.nodes()
    assert np.all(np.hypot(X - HOLE[0], Y - HOLE[1])[rest["above"]] < R + A + 0.1 + CELL)
    # the slot's strip is cut down to its floor + allowance within a stepdown, the pocket
    # floor (a level of its own) to floor + allowance
    strip = (np.abs(Y - 8.7) <= 0.4) & (np.abs(X + 10) <= 6 - R - A)
    assert strip.sum() > 100 and stock.top[strip].max() <= -1 + A + STEPDOWN
    floor = (np.abs(Y + 7) <= 5 - R - A - CELL) & (np.abs(X + 2) <= 10 - R - A - CELL) & (np.hypot(X + 2, Y + 7) > 2 + R + A + CELL)
    assert floor.sum() > 100 and np.abs(stock.top[floor] - (0 + A)).max() < 1e-6
