"""Whole jobs proven on real parts: ``sm.machine`` (rough flat + finish ball) on
``step_samples/cam_part.step`` and on corpus parts, the LinuxCNC program read back by
``rs274`` and run through the independent stock simulation (tests/stock_sim.py) on the
job's stock, one tool after the other:

- no gouge: roughing never comes nearer the part's mesh than the allowance (less the
  mesh's deflection and the 4 decimals), finishing never deeper than its tolerance;
- no rapid removes stock or touches the part, and no cut runs with the spindle stopped;
- after roughing, over every node of the stock grid the material left is at most the
  allowance plus a stepdown above the lowest the roughing tool grown by the allowance
  can stand over the node (its cutter locations on the part's height field, the
  minimum over the tool's disc): ``allowance + cusp``.  The height field samples the
  part a cell apart, so a wall can lie up to a cell beyond where it sees it: the
  reference tool is grown by one more cell and its disc shrunk by one (without that
  slack a node a hair outside the tool's reach at a wall counts as left), and a node
  left is judged again with the tool's disc on the exact triangles (a step between the
  grid's nodes, as on HEAD_BACK's seams, reads the lower side there); no node
  may be left except inside the regions the roughing reports as left (``left``: too
  small to enter without a plunge), whose measured area is at most the reported one;
- after finishing, on shallow ground (part and reachable surface below 30 degrees, at
  least two tool radii from walls steeper than 60 degrees, holes and the part's outline)
  the material left above the surface the ball can reach (the opening of the part's
  height field by the ball) is at most ``S / cos³θ + tolerance + lift``: ``S`` the
  scallop asked for, ``θ`` the local slope (parallel ball passes s apart leave
  ``S / cos²θ`` normal to a slope across them, ``S / cos³θ`` vertically; a finishing
  that holds ``S`` normal to the surface holds it too), the path's tolerance and the
  lift by its mesh deflection.  Measured vertically, so the test holds whether
  finishing is drop-cutter only or drop-cutter plus waterline;
- on steep ground (30-85 degrees, two cells clear of the outline, holes, near-vertical
  walls and the rest the ball cannot reach, where the opening stands more than ``S``
  above the part), the material left measured normal to the reachable surface is at
  most ``S + tolerance + lift``: there the waterline contours hold the scallop
  (stepcode_HEAD_BACK: 0.160, bound 0.244; 0.276 while the part's height field took every
  node of a slope steeper than 45° as beside a hole's edge, its 72° face 0.481 lower);
- on walls (faces steeper than 60 degrees, vertical ones included) the dexels along x
  and y (``Settings.side_cell`` apart in the other horizontal and in z) measure the stock left
  normal to the face at every crossing of a dexel with it, wherever the tool placed
  against the face clears the part (not under an overhang, not in a corner tighter than
  the tool, not below the stock's floor): after roughing at least the allowance (or all
  the room the line has outside the face, where the part comes back nearer) and,
  where the tool grown by the allowance and the rings' margin also clears the part a
  stepdown lower on the face (above a floor the stair is the floor's), at most ``allowance + stepdown cos θ``
  (the stair on a slope θ) plus the rings' margin
  (``roughing._boundary``: ``cell² / 16R`` + the roughing mesh's tolerance, pushed up to
  twice that), outside the reported ``left`` regions (a point under the allowance is measured
  again from the stock's end on its dexel to the part's triangles, a point over the bound
  by its distance to what the flat end swept: along a dexel a convex edge reads thinner
  and a concave corner thicker than the stock is); after finishing no cut into a wall
  beyond the tolerance and at most ``S + tolerance + lift`` left.  Wall points are the
  dexels' crossings with the part's triangles, oriented by the crossings' parity along a
  line, with the face's normal interpolated from its corners (``vertex_normals``); the
  tool's placement is sieved on a reach map of the height field and, where a point holds
  more than the bound, confirmed on the grid's nodes and on the exact triangles along the
  tool's rim (a hole a hair narrower than the tool).  Faces turned downwards are never
  reached.  Finishing leaves at most 0.008 on cam_part's walls (29816 points judged,
  bound 0.19), 0.051 on FOOT_BACK (3136), 0.080 on TAIL_MIDDLE_PART (13603), 0.025 on
  nist_ftc_11 (672), 0.238 on stepcode_HEAD_BACK (58213; its file has the solid inside
  out, the job reads it outward), 0.171 on trimesh_featuretype (77256), its eight Ø6.74
  through holes included (they were left full below z 16.7 until the waterline put fibers
  through the Ø6 ball's pits and the contours went below the flutes).
  On occt_cornetta, issue 36's 280 mm mould, at the issue's tools (flat r = 12, ball
  r = 9, S 0.09): 0.083 on its walls (39457 points), 0.082 on shallow and 0.092 on steep
  ground; a ball placed against the side of its plate would stand below the stock's bottom
  (the table): such wall points are not the tool's to reach.
  Roughing leaves at most 0.553 on cam_part's walls (allowance 0.5), 1.5-1.9 on the
  sloped walls of FOOT_BACK and TAIL_MIDDLE_PART, 2.66 on HEAD_BACK's sphere.  HEAD_BACK's
  two halves meet at x 250 in a ring step 0.01 mm high: a dexel grazing the sphere past it
  has 0.25 mm of room outside the ring, less than the allowance, and is held to that room.

Coarse settings (flat r = 5, ball r = 3, scallop 0.15, stock cells 0.25 mm) keep each
part to seconds.  No part may have stock left after roughing (before issue 26's fix
the corpus parts kept 0.04-2.5 % of their nodes, regions up to the full depth beside
walls and in concave corners, where the rings stayed a grid cell off the part).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage
from stock_sim import (RS274, Cutter, Program, Stock, _placed, _shifted, cutter_locations, disc_top,
                       normal_residual, parse_canon, part_height, reach_map, reachable, run_rs274, side_grids,
                       simulate, surface_distance, vertex_normals, wall_left, wall_points, wall_reach)

import surfmod as sm
from surfmod.inputs import to_shape
from surfmod.cam.drop_cutter import part_triangles

SAMPLES = Path(__file__).resolve().parent.parent / "step_samples"
needs_rs274 = pytest.mark.skipif(RS274 is None, reason="rs274 (Debian package linuxcnc-uspace) is not installed")
ROUNDING = 1e-4


@dataclass(frozen=True)
class Settings:
    """The job :func:`prove` makes and the judge's resolution: by default the coarse
    settings above, which keep each part to seconds."""

    r1: float = 5.0  # the roughing flat end's radius
    r2: float = 3.0  # the finishing ball's radius
    scallop: float = 0.15
    allowance: float = 0.5
    margin: float = 2.0  # the stock beyond the part
    cell: float = 0.25  # the stock simulation's cells
    side_cell: float = 0.4  # spacing of the dexels along x and y (in y or x, and in z)
    flute: float = 80.0  # both tools' flutes
    shank: float | None = None  # the shank above them (None: the tool's default)
    neck: float = 0.0  # how much narrower than the end the shank is
    deflection: float = 0.01  # the judge's mesh of the part


COARSE = Settings()
#: corpus parts (20-150 mm, pockets and holes)
CORPUS_JOBS = ["stepcode_FOOT_BACK_000.stp", "stepcode_TAIL_MIDDLE_PART.stp", "nist_ftc_11_asme1_rb.stp",
               "trimesh_featuretype.STEP", "stepcode_HEAD_BACK.stp"]


def _disc_min(a: np.ndarray, radius: float, h: float) -> np.ndarray:
    out = np.full(a.shape, np.inf)
    n = int(np.floor(radius / h))
    for di in range(-n, n + 1):
        for dj in range(-n, n + 1):
            if h * np.hypot(di, dj) <= radius:
                np.minimum(out, _shifted(a, di, dj, np.inf), out=out)
    return out


def _slope(z: np.ndarray, h: float) -> np.ndarray:
    gx, gy = np.gradient(np.where(np.isfinite(z), z, np.nan), h)
    return np.degrees(np.arctan(np.hypot(gx, gy)))


#: most (node, centre) pairs :func:`rough_rest` measures again on the exact triangles
EXACT_PAIRS = 200_000


def rough_rest(stock: Stock, top: np.ndarray, rough: sm.Operation, cell: float, triangles: np.ndarray) -> dict:
    """Stock nodes roughing left above ``allowance + stepdown`` over the lowest the tool
    can reach (slack of a cell, see above): their share outside the reported ``left``
    regions (nodes within ``R`` + a cell of a reported ring) and their area inside.

    The grid's lowest misses a step lying between its nodes: stepcode_HEAD_BACK's two
    halves meet in seams along y 0 and x 250, on the grid's lines, and its nodes there read
    the lower side (OCCT: the flat end of radius 5.75 the grid stood 36.448 high at
    (197, 0) cuts the part 0.53 higher at (202.75, 0)).  So each node left outside the
    reported regions is judged again at the centres that left it, with the disc's highest
    point on the exact ``triangles`` (:func:`stock_sim.disc_top`)."""
    R, rep = rough.tool.radius, rough.report
    allowance, stepdown = rep["allowance"], rep["stepdown"]
    radius = R + allowance + cell
    grown = cutter_locations(top, Cutter("flat", radius), cell)
    lowest = np.maximum(_disc_min(grown, R - cell, cell), stock.bottom)
    above = stock.top - (lowest + allowance + stepdown) > 1e-6
    declared = np.zeros(above.shape, bool)
    X, Y = stock.nodes()
    for g in rep["left"]:
        for x, y in g["ring"]:
            declared |= np.hypot(X - x, Y - y) <= R + cell
    nodes = np.argwhere(above & ~declared)
    n = int(np.floor((R - cell) / cell))
    di, dj = np.mgrid[-n:n + 1, -n:n + 1]
    near = cell * np.hypot(di, dj) <= R - cell
    di, dj = di[near], dj[near]
    if len(nodes) * len(di) > EXACT_PAIRS:
        raise ValueError(f"rough_rest: {len(nodes)} nodes left, more than {EXACT_PAIRS // len(di)} to judge again")
    pairs = []
    for i, j in nodes:
        ci, cj = i + di, j + dj
        ok = (ci >= 0) & (ci < above.shape[0]) & (cj >= 0) & (cj < above.shape[1])
        ci, cj = ci[ok], cj[ok]
        claim = np.maximum(grown[ci, cj], stock.bottom) + allowance + stepdown < stock.top[i, j] - 1e-6
        pairs += [(i, j, a, b) for a, b in zip(ci[claim], cj[claim])]
    if pairs:
        pairs = np.array(pairs)
        centres, which = np.unique(pairs[:, 2:], axis=0, return_inverse=True)
        exact = disc_top(triangles, np.column_stack([X[centres[:, 0], centres[:, 1]], Y[centres[:, 0], centres[:, 1]]]),
                         radius)
        low = np.maximum(exact[which.ravel()], stock.bottom)
        still = stock.top[pairs[:, 0], pairs[:, 1]] - (low + allowance + stepdown) > 1e-6
        above[tuple(nodes.T)] = False
        above[pairs[still, 0], pairs[still, 1]] = True
    return {"share": float(np.mean(above & ~declared)), "declared_area": float(sum(g["area"] for g in rep["left"])),
            "left_area": float((above & declared).sum()) * cell * cell, "above": above}


def sweep_sides(sides, prog: Program, tool: int, cutter: Cutter):
    moves = [m for m in prog.moves if m.tool == tool]
    a, b = np.array([m.a for m in moves]), np.array([m.b for m in moves])
    for dex in sides:
        dex.cut(cutter, a, b)


def walls_left(sides, walls) -> np.ndarray:
    return np.concatenate([wall_left(dex, w) for dex, w in zip(sides, walls)])


#: most wall points :func:`flat_thickness` confirms (each against every move of the tool)
CONFIRM_LIMIT = 5_000


def flat_thickness(points: np.ndarray, prog: Program, tool: int, radius: float) -> np.ndarray:
    """The stock left at each wall point by the flat end ``tool`` of ``radius``: its
    distance to what the feed moves swept (each move's disc, at the lower of its ends, and
    the cylinder above it).  Along a dexel the stock's end at a concave corner lies farther
    than its nearest point (the gear's recess corner: 0.68 along the dexels where the tool
    stayed 1.52 from the wall, 0.52 of stock)."""
    if len(points) > CONFIRM_LIMIT:
        raise ValueError(f"flat_thickness: {len(points)} points, more than {CONFIRM_LIMIT}")
    moves = [m for m in prog.moves if m.tool == tool and not m.rapid]
    a, b = np.array([m.a for m in moves]), np.array([m.b for m in moves])
    ab, z0 = b[:, :2] - a[:, :2], np.minimum(a[:, 2], b[:, 2])
    out = np.empty(len(points))
    for k, p in enumerate(points):
        t = np.clip(((p[:2] - a[:, :2]) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0.0, 1.0)
        side = np.maximum(np.hypot(*(p[:2] - a[:, :2] - t[:, None] * ab).T) - radius, 0.0)
        out[k] = np.where(p[2] >= z0, side, np.hypot(side, z0 - p[2])).min()
    return out


def exact_where_thin(sides, walls, left: np.ndarray, bound: float, tri: np.ndarray) -> np.ndarray:
    """``left`` with the wall points under ``bound`` (not cut into, the stock's end on the
    dexel before the part's next crossing) measured again from that end to the part's
    triangles: at a convex edge the plane through a wall point comes nearer the stock than
    the part does (the gear's tooth tips: 0.441 by the plane where the roughing's tool
    stayed 1.519 from the part, 0.519 of allowance)."""
    out, k = left.copy(), 0
    for dex, w in zip(sides, walls):
        thin = np.flatnonzero((left[k:k + len(w)] < bound) & (left[k:k + len(w)] >= 0))
        along = dex.thickness(w.line[thin], w.pos[thin], w.outward[thin])
        thin, along = thin[along <= w.room[thin]], along[along <= w.room[thin]]
        end = w.point[thin].copy()
        end[:, dex.axis] += w.outward[thin] * along
        d = surface_distance(tri, end, bound + 1.0)
        out[k + thin] = np.where(np.isfinite(d), d, out[k + thin])
        k += len(w)
    return out


def wall_check(walls, floor, stock: Stock, cutter: Cutter, left: np.ndarray, bound: np.ndarray, offset: float,
               slack: float, tri: np.ndarray, cell: float, below: float = 0.0):
    """Wall points left thicker than ``bound`` that the tool (grown by ``offset``) can touch
    (and ``below`` lower on the face), and the points the quick reach map lets it touch
    less those over the bound that the tool placed at each over the grid's nodes and the
    exact triangles cannot touch (the judged footprint; the quick map is a little generous
    with points within the bound)."""
    kw = dict(offset=offset, below=below, slack=slack)
    quick = reach_map(floor, cell, cutter, offset=offset, slack=slack)
    reach = np.concatenate([wall_reach(w, floor, stock.x, stock.y, cutter, quick=quick, **kw) for w in walls])
    # the tip stands on the stock's bottom at lowest (the table), also where the tool is
    # placed beyond the stock's grid, where wall_reach sees no floor (a ball r 9 against
    # the side of occt_cornetta's plate, 2 mm inside the stock's edge, 9 mm below it)
    reach &= np.concatenate([_placed(w, cutter, offset)[:, 2] for w in walls]) >= stock.bottom - 1e-9
    over = reach & (left > bound)
    if over.any():
        k = np.cumsum([0] + [len(w) for w in walls])
        for w, a, b in zip(walls, k[:-1], k[1:]):
            cand = np.flatnonzero(over[a:b])
            over[a + cand] = wall_reach(w.take(cand), floor, stock.x, stock.y, cutter, triangles=tri, **kw)
    judged = reach & ((left <= bound) | over)  # less the candidates the exact placement refused
    return over, judged


def prove(path: Path, tmp_path: Path, s: Settings = COARSE) -> dict:
    shape = to_shape(path)
    rough, finish = (sm.Tool(kind, r, flute_length=s.flute, shank_length=s.shank, shank_radius=r - s.neck)
                     for kind, r in (("flat", s.r1), ("ball", s.r2)))
    job = sm.machine(shape, s.margin, [sm.Rough(rough, allowance=s.allowance), sm.Finish(finish, scallop=s.scallop)])
    ngc = tmp_path / "job.ngc"
    sm.export_gcode(job, ngc, post="linuxcnc")
    prog = parse_canon(run_rs274(ngc, tmp_path / "job.txt"), arc_chord=1e-4)
    assert prog.tool_changes == [1, 2] and prog.ended
    tri, deflection, (_, owner) = part_triangles(shape, s.deflection, face_index=True)
    stock = Stock(job.stock, s.cell)
    top = part_height(tri, stock.x, stock.y, deflection=deflection)  # no face lifted over a hole's chord
    bottom = float(job.stock[0, 2])
    floor = np.where(np.isfinite(top), top, bottom)  # the tool cannot go below the stock
    sides = side_grids(job.stock, s.side_cell)
    normals = vertex_normals(tri, owner)
    walls = [wall_points(tri, dex, normals=normals) for dex in sides]
    wall_nz = np.abs(np.concatenate([w.normal[:, 2] for w in walls]))

    # roughing
    rep = simulate(Program([m for m in prog.moves if m.tool == 1]), {1: Cutter("flat", s.r1)}, stock, top)
    assert rep.gouge <= -s.allowance + deflection + ROUNDING, str(rep)
    assert rep.rapid_cut <= 1e-9 and rep.rapid_part < 0 and rep.cut_without_spindle == 0, str(rep)
    rest = rough_rest(stock, top, job.operations[0], s.cell, tri)
    share = rest["share"]
    assert share == 0, f"roughing leaves {share:.3%} of the stock above allowance + cusp, unreported"
    assert rest["left_area"] <= rest["declared_area"] + 1e-9, rest
    # roughing on the walls (see the module's docstring): never nearer than the allowance,
    # at most allowance + stepdown cos θ + the rings' margin where the tool grown by both
    # touches the wall and a stepdown lower on it
    rough_rep = job.operations[0].report
    sweep_sides(sides, prog, 1, Cutter("flat", s.r1))
    left = exact_where_thin(sides, walls, walls_left(sides, walls), s.allowance - deflection - ROUNDING, tri)
    # where the part comes back along the line nearer than the allowance (a slit, or a line
    # grazing the part past a step: stepcode_HEAD_BACK's 0.01 mm ring at x 250), the stock
    # there can hold no more than that room
    room = np.concatenate([w.room * np.abs(w.normal[:, dex.axis]) for dex, w in zip(sides, walls)])
    short = left - np.minimum(s.allowance, room)
    assert short.min() >= -(deflection + ROUNDING), f"roughing cuts {-short.min():.4f} into a wall"
    ring = 2 * (rough_rep["cell"] ** 2 / (16 * s.r1) + rough_rep["tolerance"])
    rough_bound = s.allowance + rough_rep["stepdown"] * wall_nz + ring + deflection + ROUNDING
    over, rough_reach = wall_check(walls, floor, stock, Cutter("flat", s.r1), left, rough_bound, s.allowance + ring,
                                   deflection, tri, s.cell, rough_rep["stepdown"])
    declared = np.zeros(len(left), bool)
    pts = np.concatenate([w.point for w in walls])
    for g in rough_rep["left"]:
        for x, y in g["ring"]:
            declared |= np.hypot(pts[:, 0] - x, pts[:, 1] - y) <= s.r1 + s.cell
    over &= ~declared
    over[over] = flat_thickness(pts[over], prog, 1, s.r1) > rough_bound[over]
    assert not over.any(), f"roughing leaves {left[over].max():.4f} on {over.sum()} wall points, e.g. {pts[over][0]}"
    rough_wall = float(left[rough_reach].max(initial=0.0))
    roughed = copy.deepcopy(sides)

    # finishing on the roughed stock
    fin = job.operations[1]
    rep = simulate(Program([m for m in prog.moves if m.tool == 2]), {2: Cutter("ball", s.r2)}, stock, top)
    tol = fin.report["tolerance"]
    assert rep.gouge <= tol + deflection + ROUNDING, str(rep)
    assert rep.rapid_cut <= 1e-9 and rep.rapid_part < 0 and rep.cut_without_spindle == 0, str(rep)
    reach = reachable(np.where(np.isfinite(top), top, bottom), Cutter("ball", s.r2), s.cell)
    theta = np.maximum(_slope(top, s.cell), _slope(reach, s.cell))
    wall = ~np.isfinite(top) | ~(np.nan_to_num(theta, nan=90.0) <= 60)
    pad = int(np.ceil(2 * s.r2 / s.cell))
    near = ndimage.binary_dilation(wall, iterations=pad)
    near[:pad] = near[-pad:] = True
    near[:, :pad] = near[:, -pad:] = True
    shallow = ~near & (np.nan_to_num(theta, nan=90.0) < 30)
    residual = (stock.top - reach)[shallow]
    lift = fin.report["toolpath"].deflection
    bound = s.scallop / np.cos(np.radians(theta[shallow])) ** 3 + tol + lift
    assert shallow.sum() > 1000
    worst = float((residual - bound).max())
    assert worst <= 0, f"residual {residual.max():.4f} above S/cos³θ + tol + lift by {worst:.4f}"
    # steep ground the ball reaches (30-85 degrees; not within two cells of the outline,
    # holes, near-vertical walls or the rest the ball cannot reach): normal to the reachable
    # surface the material left is at most S + tolerance + lift
    th = np.nan_to_num(theta, nan=90.0)
    rest = np.isfinite(top) & (reach - top > s.scallop)
    off = ndimage.binary_dilation(~np.isfinite(top) | (th >= 85) | rest, iterations=2)
    off[:2] = off[-2:] = True
    off[:, :2] = off[:, -2:] = True
    steep = ~off & (th >= 30) & (th < 85)
    normal = normal_residual(stock.top, reach, s.cell)[steep]
    steep_worst = float(np.nanmax(normal, initial=0.0))
    if steep_worst > s.scallop + tol + lift:
        i, j = np.argwhere(steep)[np.nanargmax(normal)]
        raise AssertionError(f"normal residual {steep_worst:.4f} on steep ground > S + tol + lift "
                             f"{s.scallop + tol + lift:.4f}, at ({stock.x[i]:.3f}, {stock.y[j]:.3f}, {top[i, j]:.3f}), "
                             f"slope {th[i, j]:.1f} deg")
    # walls (steeper than 60 degrees) through the dexels along x and y: where the ball can
    # touch the wall, at most S + tolerance + lift is left normal to it, and no cut into it
    left, over, reach = judge_finish(sides, walls, prog, Cutter("ball", s.r2), floor, stock, deflection, tri,
                                     s.scallop + tol + lift, s)
    assert left.min() >= -(tol + deflection + ROUNDING), f"finishing cuts {-left.min():.4f} into a wall"
    assert not over.any(), f"finishing leaves {left[over].max():.4f} > S + tol + lift on {over.sum()} wall points, " \
                           f"e.g. {pts[over][0]}"
    return {"job": job, "rest_share": share, "residual": float(residual.max()), "nodes": int(shallow.sum()),
            "steep_nodes": int(steep.sum()), "steep_residual": steep_worst, "wall_points": len(left),
            "wall_nodes": int(reach.sum()), "wall_residual": float(left[reach].max(initial=0.0)),
            "rough_wall": rough_wall, "rough_wall_nodes": int(rough_reach.sum()),
            # to judge the finishing again: the walls, the roughed dexels and what bounds them
            "finish": lambda cutter: judge_finish(roughed, walls, prog, cutter, floor, stock, deflection, tri,
                                                  s.scallop + tol + lift, s)}


def judge_finish(sides, walls, prog, cutter, floor, stock, deflection, tri, bound, s: Settings):
    """Stock left on the walls after the finishing moves swept with ``cutter``, the points
    over ``bound`` the finishing ball (radius ``s.r2``) can touch, and the points judged."""
    sweep_sides(sides, prog, 2, cutter)
    left = walls_left(sides, walls)
    return (left,) + wall_check(walls, floor, stock, Cutter("ball", s.r2), left, bound, 0.0, deflection, tri, s.cell)


@needs_rs274
def test_cam_part_job_in_stock(tmp_path):
    got = prove(SAMPLES / "cam_part.step", tmp_path)
    print({k: v for k, v in got.items() if k not in ("job", "finish")})
    # the top of the mould is shallow: most of it is judged; so are its walls
    assert got["wall_nodes"] > 25_000 and got["rough_wall_nodes"] > 20_000
    # the same program run with a ball 0.2 smaller than it was made for: the walls show it
    left, over, _ = got["finish"](Cutter("ball", COARSE.r2 - 0.2))
    assert over.sum() > 1000 and left[over].max() > 0.2
    assert got["nodes"] > 40_000 and got["residual"] > COARSE.scallop / 2
    # the job's own verdict measures what this judge does: its residual after finishing
    # more than two thirds of the scallop (0.125 of 0.15) and within its limit, its walls'
    # the dexels' (0.0079)
    v = got["job"].verification
    assert v.ok, str(v)
    residual = next(f for f in v.findings if f.what.startswith("residual after finishing"))
    assert 2 / 3 * COARSE.scallop < residual.worst <= residual.limit < 7 / 6 * COARSE.scallop, residual
    walls = next(f for f in v.findings if f.what.startswith("residual on walls"))
    assert abs(walls.worst - got["wall_residual"]) < 1e-3, (walls, got["wall_residual"])


@needs_rs274
@pytest.mark.corpus
@pytest.mark.parametrize("name", sorted(CORPUS_JOBS))
def test_corpus_job_in_stock(tmp_path, corpus_dir, name):
    got = prove(corpus_dir / name, tmp_path)
    print(name, {k: v for k, v in got.items() if k not in ("job", "finish")})


#: a part that needs a 1 mm tool (issue 36): a 60 mm Fusion 360 spur gear of ten teeth,
#: 5 mm thick, its tooth roots rounded 1.59 mm and a 2 mm deep recess with 2 mm corners;
#: a flat r = 1 roughs and a ball r = 0.8 finishes (the issue's tools), the scallop 2.5 %
#: of the ball's radius, the judge's stock cells 0.1 mm (about a quarter of the stepover)
SMALL_TOOL_JOB = "f360grbl_gear.step", Settings(r1=1.0, r2=0.8, scallop=0.02, cell=0.1)


def prove_with(job: tuple[str, Settings], corpus_dir: Path, tmp_path: Path, least: dict | None = None) -> dict:
    """:func:`prove` on the corpus part ``job[0]`` with the settings ``job[1]``; with
    ``least``, each named count of the proof (nodes judged shallow or steep, wall points)
    above that."""
    name, settings = job
    got = prove(corpus_dir / name, tmp_path, settings)
    shown = {k: v for k, v in got.items() if k not in ("job", "finish")}
    print(name, shown)
    assert all(got[key] > count for key, count in (least or {}).items()), shown
    return got


@needs_rs274
@pytest.mark.corpus
def test_corpus_job_with_a_small_tool(tmp_path, corpus_dir):
    got = prove_with(SMALL_TOOL_JOB, corpus_dir, tmp_path)
    fin = got["job"].operations[1].report
    # the ball reaches the tooth roots (their fillets are larger than it) and the floor
    # of the recess: most of the gear's top is judged shallow ground
    assert got["nodes"] > 50_000 and fin["stepover"] < 0.4, {k: v for k, v in got.items() if k != "job"}


#: walls under overhangs: a 30 x 30 mm T-slot profile 40 mm long lying on its side (from
#: three-cad-viewer's examples, never tuned to), slots whose lips overhang their undercuts
#: on the top and both sides; a flat r = 1.5 roughs and a ball r = 1 finishes (5 and 3 % of
#: its width) on 40 mm flutes, the scallop 2 % of the ball's radius, the judge's stock
#: cells 0.1 mm (a quarter of the 0.4 mm stepover) and its wall dexels 0.2 mm apart.  The
#: slots' hidden walls are material the dexels keep and no tool from above can reach.
OVERHANG_JOB = "tcv_profile4040.step", Settings(r1=1.5, r2=1.0, scallop=0.02, cell=0.1, side_cell=0.2, flute=40.0)


@needs_rs274
@pytest.mark.corpus
def test_corpus_job_under_overhangs(tmp_path, corpus_dir):
    # the profile's top and slot floors are judged shallow ground (60,333 nodes: residual
    # 0.0192), the rounded edges steep ground (5,502) and the walls through the
    # dexels (54,324 of 142,540 points reached: 0.0087); the undercuts stay unreached
    prove_with(OVERHANG_JOB, corpus_dir, tmp_path,
               least={"nodes": 40_000, "steep_nodes": 3_000, "wall_nodes": 40_000})


#: issue 36's freeform mould: OCCT's test part for its bug 27693, 280 x 160 x 62 mm, a
#: raised block of 74 B-spline faces with rounded walls on a plate, a recessed slot with
#: two holes; a flat r = 12 roughs and a ball r = 9 finishes (4.3 and 3.2 % of its length,
#: the issue's tools), the scallop 1 % of the ball's radius, the judge's stock cells 0.5 mm
#: (a fifth of the 2.5 mm stepover) and its wall dexels 0.8 mm apart (at 0.4 the dexels
#: would meet the moves 7.6e7 times, above the judge's 6e7)
MOULD_JOB = "occt_cornetta.stp", Settings(r1=12.0, r2=9.0, scallop=0.09, cell=0.5, side_cell=0.8)


@needs_rs274
@pytest.mark.corpus
def test_corpus_job_on_a_freeform_mould(tmp_path, corpus_dir):
    # the plate and the block's top are judged shallow ground (26,247 nodes; the rest is
    # within two ball radii of a wall), the block's rounded walls steep ground (5,323) and
    # the walls through the dexels (39,457 points)
    prove_with(MOULD_JOB, corpus_dir, tmp_path,
               least={"nodes": 20_000, "steep_nodes": 4_000, "wall_nodes": 30_000})


#: issue 36's pocketed plate larger than 500 mm: NIST CTC-02, 680 x 860 x 400 mm, pockets
#: 330 mm deep from its top (floors at z -290), bosses, ribs and bores; a flat r = 30
#: roughs and a ball r = 25 finishes (60 and 50 mm tools) on 420 mm of reach (flutes
#: 100 mm, above them a shank as wide as the end: beside the walls taller than the
#: flutes the job keeps it off the roughing's allowance), the scallop 2 % of the ball's radius;
#: the judge's stock cells 2 mm (a fifth of the 10 mm stepover), its wall dexels 4 mm
#: apart (at 2 mm the finishing's 638,674 moves as rs274 reads them back would meet them
#: 1.75e8 times, above the judge's 6e7) and its mesh 0.05 mm (the file's own edges are
#: 0.097 off its faces).  The proof takes about 8 CPU minutes, most of them the job itself
#: (its waterline, drop-cutter and meshing, the verification's gouge measure): marked
#: ``heavy``, run with ``python -m pytest -q -m heavy``, outside CI
PLATE_JOB = "nist_ctc_02_asme1_rc.stp", Settings(r1=30.0, r2=25.0, scallop=0.5, cell=2.0, side_cell=4.0, flute=100.0,
                                               shank=320.0, deflection=0.05)


@needs_rs274
@pytest.mark.heavy
def test_corpus_job_on_a_pocketed_plate(tmp_path, corpus_dir):
    # the floors and the top are judged shallow ground (22,182 nodes: residual 0.307), the
    # rounded edges steep ground (737: 0.346), the pockets' walls through the dexels
    # (36,363 of 97,397 points: 0.516 after finishing, 29,084 after roughing)
    prove_with(PLATE_JOB, corpus_dir, tmp_path,
               least={"nodes": 20_000, "steep_nodes": 500, "wall_nodes": 30_000})
