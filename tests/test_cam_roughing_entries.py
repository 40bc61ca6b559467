"""A roughing entry never comes down rapidly beside the stock the levels above left, and
the verifier sees a rapid that grazes stock between its nodes (issue 36: on the gear
``f360grbl_gear.step`` a ramp entry rapided down 0.996 mm from a sliver the levels above
left 1.000 mm from their rings; neither height-field stock held it).

The case built here: a round hole in which the tool (flat r 1, allowance 0.3) can stand
only within 0.3 mm of the axis, too narrow for more than the boundary ring at each
level.  Every ring is entered by a ramp along itself, and every ring point lies where
the level above stood, a hair from the allowance it left on the hole's wall up to the
top face.  An entry that rapids down to the level above (+0.5) rubs that stock (by the
boundary's bisection, a few µm, or not at all: luck).  The judge is the tests' own stock
simulation on a grid finer than the product's, rapids going down measured with the tool
0.05 mm wider: none may come within that of stock.

The verifier's case: a hand-made program cuts a channel with a flat end, then rapids
down beside it, the tool 4 µm into the channel's wall where no node of the verifier's
stock lies (its nodes stand a cell apart, the wall between two of them).
"""

from __future__ import annotations

from dataclasses import replace

import build123d as bd
import numpy as np
from stock_sim import Cutter, Program, Stock, _pieces, read_back

import surfmod as sm
from surfmod.cam.roughing import FEED, RAPID, Motion
from surfmod.cam.verify import stock_cells, verify_job

R, A, STEPDOWN, STEPOVER, MARGIN = 1.0, 0.3, 1.0, 0.8, 1.0
JUDGE_CELL, WIDER = 0.04, 0.05


def hole_part():
    part = bd.Box(12, 12, 4)  # z from -2 to 2
    return part - bd.Pos(0, 0, 1) * bd.Cylinder(R + A + 0.3, 4)  # floor z -1


def judge_rapids(prog: Program, cutter: Cutter, stock: Stock, wider: float) -> float:
    """The deepest a rapid going down comes into the stock with ``cutter`` grown by
    ``wider`` (the feeds cut with ``cutter``, in the program's order)."""
    grown, worst = Cutter(cutter.kind, cutter.radius + wider, cutter.corner), -np.inf
    for mv in prog.moves:
        down = mv.rapid and mv.b[2] < mv.a[2]
        for a, b in _pieces(mv.a, mv.b, cutter.radius):
            if mv.rapid:
                if down:
                    win, env = stock.sweep(grown, a, b)
                    if win is not None:
                        worst = max(worst, float((stock.top[win] - env).max(initial=-np.inf)))
                continue
            win, env = stock.sweep(cutter, a, b)
            if win is not None:
                np.minimum(stock.top[win], env, out=stock.top[win])
    return worst


def test_entries_come_down_clear_of_the_stock_left(tmp_path):
    job = sm.machine(hole_part(), MARGIN, [sm.Rough(sm.Tool("flat", R, flute_length=20), stepdown=STEPDOWN,
                                                    allowance=A, stepover=STEPOVER)], verify=False)
    op = job.operations[0]
    assert not op.report["left"]
    # the hole is entered at every level below the top face, each by a ramp
    p, kind = op.motion.points, op.motion.kind
    down = (kind[1:] == RAPID) & (p[1:, 2] < p[:-1, 2]) & (np.hypot(p[1:, 0], p[1:, 1]) < 1)
    assert down.sum() >= 3
    ngc = tmp_path / "rough.ngc"
    sm.export_gcode(job, ngc, post="linuxcnc")
    prog = read_back(ngc, arc_chord=1e-4)
    worst = judge_rapids(prog, Cutter("flat", R), Stock(job.stock, JUDGE_CELL), WIDER)
    assert worst <= 0, f"a rapid comes down within {WIDER} of stock, {worst:.3f} below its top"


def test_the_verifier_sees_a_rapid_graze_stock_between_its_nodes():
    part = bd.Box(20, 20, 2)  # z from -1 to 1; the stock's top at 3
    job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", R, flute_length=20), allowance=A)], verify=False)
    lo, hi = job.stock
    cell = stock_cells(job.stock, R / 4)[0]  # the verifier's cells: a roughing alone, a quarter radius
    # the channel's wall (its cutter line + R) half a cell beyond a column of nodes; the
    # rapid's tool reaches 4 µm past it, short of the next column
    wall = lo[0] + (int(20 / cell) + 0.5) * cell
    x, y, zc, safe = wall - R, 0.5 * (lo[1] + hi[1]), hi[2] - 1.0, job.safe_height
    pts = np.array([[x, lo[1] - 3, safe], [x, lo[1] - 3, zc], [x, hi[1] + 3, zc], [x, hi[1] + 3, safe],
                    [x + 0.004, y, safe], [x + 0.004, y, zc + 0.5], [x + 0.004, y, safe]])
    kind = np.array([RAPID, RAPID, FEED, RAPID, RAPID, RAPID, RAPID], np.int8)
    op = replace(job.operations[0], motion=Motion(pts, kind))
    found = next(f for f in verify_job(replace(job, operations=(op,))).findings if f.what == "rapids")
    assert not found.ok and found.worst > 0.4, found
