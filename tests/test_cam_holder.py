"""Shank and holder collisions: a deep box pocket a short tool cannot reach to the floor.

The part is a 24 x 24 x 10 block (top z = 5) with a 12 x 12 pocket down to z = -3, cut from
stock that is the block itself.  A holder of radius 7 is wider than the pocket (half
width 6): wherever its bottom is below the block's top it stands on the block.  The judge
is exact geometry on that box, applied to the program as written (read back by the
tests' own G-code reader, :mod:`stock_sim`), not the package's checks.
"""

import json
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import build123d as bd
import numpy as np
import pytest
from stock_sim import parse_gcode

import surfmod as sm
from surfmod.cli import main
from surfmod.cam.drop_cutter import part_triangles
from surfmod.cam.holder import clear_body, part_sink
from surfmod.cam.rest import StockModel
from surfmod.cam.roughing import FEED, RAPID, Motion
from surfmod.cam.tool import load_tool_table
from surfmod.cam import wall_dexels
from surfmod.cam.verify import cusp_clearance, verify_job

TOP, FLOOR, HALF, BLOCK = 5.0, -3.0, 6.0, 12.0
HOLDER = 7.0


def pocket():
    return bd.Box(24, 24, 10) - bd.Pos(0, 0, 1) * bd.Box(12, 12, 8)


def tools(flute, shank_length):
    common = dict(flute_length=flute, shank_length=shank_length, holder_radius=HOLDER, holder_length=20.0)
    return sm.Tool("flat", 2.0, **common), sm.Tool("ball", 1.5, **common)


def job_for(flute, shank_length, **kw):
    rough, finish = tools(flute, shank_length)
    return sm.machine(pocket(), 0.0, [sm.Rough(rough, stepdown=2.0, allowance=0.3),
                                     sm.Finish(finish, scallop=0.05)], **kw)


@pytest.fixture(scope="module")
def short_job():
    return job_for(4.0, 0.0)


@pytest.fixture(scope="module")
def long_job():
    return job_for(10.0, 1.0)


def holder_depth(a, b, radius, bottom_above_tip):
    """Exact: how far below the block's top face (the square of half width BLOCK less the
    open pocket of half width HALF) a flat-bottomed cylinder of ``radius`` at
    ``bottom_above_tip`` over the tip stands where it overlaps the face, moved from ``a``
    to ``b`` (-inf where it never overlaps); each position exactly, 0.01 mm apart."""
    n = int(np.ceil(np.linalg.norm(b - a) / 0.01)) + 1
    p = a + np.linspace(0, 1, n)[:, None] * (b - a)
    inside_pocket = (np.abs(p[:, 0]) + radius <= HALF) & (np.abs(p[:, 1]) + radius <= HALF)
    gap = np.hypot(np.maximum(np.abs(p[:, 0]) - BLOCK, 0), np.maximum(np.abs(p[:, 1]) - BLOCK, 0))
    over = ~inside_pocket & (gap < radius)
    return float(np.max(TOP - (p[over, 2] + bottom_above_tip), initial=-np.inf))


def holder_hits(a, b, radius, bottom_above_tip):
    """Does the cylinder stand below the block's top face anywhere along the move?"""
    return holder_depth(a, b, radius, bottom_above_tip) > 1e-6


def written(job, tmp_path):
    path = tmp_path / "job.ngc"
    sm.export_gcode(job, path)
    return parse_gcode(path.read_text())


def test_short_tool_leaves_the_floor_and_never_collides(short_job, tmp_path):
    prog = written(short_job, tmp_path)
    for op in short_job.operations:
        t = op.tool
        moves = [m for m in prog.moves if m.tool == t.number]
        assert moves
        bottom = t.flute_length + t.shank_length
        # at every written move the holder clears the block: exact, on the box
        assert not any(holder_hits(m.a, m.b, HOLDER, bottom) for m in moves)
        # nothing of it goes below the block's top less the holder's height over the tip
        assert min(min(m.a[2], m.b[2]) for m in moves if not m.rapid) >= TOP - bottom - 1e-3
        held = op.report["holder"]
        assert held is not None and held.moves > 0
        # the floor under the pocket is left: most of its 144 mm², the deepest point on it
        assert 100.0 < held.area <= 12.0 * 12.0
        assert abs(held.deepest[0]) < HALF and abs(held.deepest[1]) < HALF
        assert abs(held.deepest[2] - (FLOOR + (0.3 if op.name == "roughing" else 0.0))) < 0.01
        assert "left uncut" in str(op)
    v = short_job.verification
    assert v.ok, str(v)
    assert [f.what for f in v.findings if f.what.startswith("holder")] == [
        "holder and shank, roughing (tool 1)", "holder and shank, finishing (tool 2)"]
    assert any("keeps the finishing tool from" in n for n in v.notes)


def test_long_tool_cuts_the_same_pocket(long_job, tmp_path):
    prog = written(long_job, tmp_path)
    assert all(op.report["holder"] is None for op in long_job.operations)
    assert long_job.verification.ok, str(long_job.verification)
    finish = long_job.operations[1].tool
    lowest = min(min(m.a[2], m.b[2]) for m in prog.moves if m.tool == finish.number and not m.rapid
                 and max(abs(m.a[0]), abs(m.a[1])) < HALF)
    assert abs(lowest - FLOOR) < 0.01  # the ball's tip on the pocket's floor
    bottom = finish.flute_length + finish.shank_length
    assert not any(holder_hits(m.a, m.b, HOLDER, bottom) for m in prog.moves if m.tool == finish.number)


def test_strict_refuses(tmp_path, capsys):
    with pytest.raises(sm.SurfmodError, match="strict"):
        job_for(4.0, 0.0, strict=True, verify=False)
    step = tmp_path / "pocket.step"
    bd.export_step(pocket(), str(step))
    table = tmp_path / "tools.json"
    table.write_text(json.dumps({"tool": [
        {"number": 1, "kind": "flat", "radius": 2.0, "flute_length": 4.0, "shank_length": 0.0,
         "holder_radius": HOLDER, "holder_length": 20.0},
        {"number": 2, "kind": "ball", "radius": 1.5, "flute_length": 4.0, "shank_length": 0.0,
         "holder_radius": HOLDER, "holder_length": 20.0}]}))
    out = tmp_path / "job.ngc"
    argv = ["machine", str(step), "--out", str(out), "--stock-margin", "0", "--rough", "flat:2", "--finish",
            "ball:1.5", "--scallop", "0.05", "--stepdown", "2", "--allowance", "0.3", "--tools", str(table),
            "--no-progress", "--no-verify", "--strict"]
    assert main(argv) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "strict" in err[0] and "holder" in err[0]
    assert not out.exists()


def test_tool_body_fields(tmp_path):
    t = sm.Tool("flat", 2.0)
    # the defaults: shank as the end, sticking out two radii, a holder 2.5 radii wide, 8 long
    assert (t.shank_radius, t.shank_length, t.holder_radius, t.holder_length, t.holder_top_radius) == (
        2.0, 4.0, 5.0, 16.0, 5.0)
    assert t.body.tolist() == [[2.0, 12.0, 4.0], [5.0, 16.0, 16.0]]
    cone = sm.Tool("ball", 1.0, flute_length=5.0, shank_length=1.0, holder_radius=3.0, holder_length=8.0,
                   holder_top_radius=7.0)
    b = cone.body
    assert len(b) == 1 + 8 and b[1].tolist() == [3.5, 6.0, 1.0] and b[-1].tolist() == [7.0, 13.0, 1.0]
    # every slice's cylinder holds the cone: its radius at least the cone's over the slice
    h = np.linspace(6.0, 14.0, 801)
    cone_r = 3.0 + (h - 6.0) / 8.0 * 4.0
    held = np.array([b[1:][b[1:, 1] <= x + 1e-12, 0].max() for x in h])
    assert np.all(held >= cone_r - 1e-12)
    toml = tmp_path / "t.toml"
    toml.write_text('[[tool]]\nnumber = 1\nkind = "flat"\nradius = 3\nflute_length = 25\nshank_radius = 3.5\n'
                    'shank_length = 10\nholder_radius = 12\nholder_length = 40\nholder_top_radius = 16\n')
    got = load_tool_table(toml)[1]
    assert (got.shank_radius, got.shank_length, got.holder_radius, got.holder_length, got.holder_top_radius) == (
        3.5, 10.0, 12.0, 40.0, 16.0)


@pytest.mark.parametrize("fields, word", [
    (dict(shank_radius=0), "shank_radius"),
    (dict(shank_length=-1), "shank_length"),
    (dict(holder_radius=1.0, shank_radius=2.0), "holder_radius"),
    (dict(holder_radius=-3), "holder_radius"),
    (dict(holder_length=0), "holder_length"),
    (dict(holder_top_radius=float("nan")), "holder_top_radius"),
    (dict(holder_length="long"), "holder_length"),
])
def test_tool_body_bad_input(tmp_path, fields, word):
    with pytest.raises(sm.SurfmodError, match=word):
        sm.Tool("flat", 2.0, **fields)
    table = tmp_path / "t.json"
    table.write_text(json.dumps({"tool": [dict(number=1, kind="flat", radius=2.0, **fields)]}, allow_nan=True))
    with pytest.raises(sm.SurfmodError, match=word):
        load_tool_table(table)


def test_close_calls_settled_exactly():
    """Over a sphere of radius 10 the mesh lies below the surface by up to its deflection:
    a holder hovering half a deflection above the top is flagged by the mesh's margin and
    cleared by OCCT's exact distance; one a deflection into the sphere stays flagged."""
    part = bd.Sphere(10)
    triangles, deflection = part_triangles(part, 0.05)
    tool = sm.Tool("ball", 1.0, flute_length=3.0, shank_length=0.0, holder_radius=4.0, holder_length=10.0)
    hover = np.array([[0.0, 0.0, 7.0 + deflection / 2], [0.5, 0.0, 7.2 + deflection / 2]])
    assert 0 < part_sink(triangles, deflection, tool, hover, 0.01)[0] <= deflection
    assert part_sink(triangles, deflection, tool, hover, 0.01, part)[0] == -np.inf
    into = hover - [0.0, 0.0, 1.5 * deflection]  # the holder's bottom a deflection below z = 10
    assert part_sink(triangles, deflection, tool, into, 0.01, part)[0] > 0


def test_rest_machining_is_held_too(tmp_path):
    """The rest ball in the same short holder finds the floor left and would go there: its
    moves are held back as well, reported, and none of them written collides."""
    rough, finish = tools(4.0, 0.0)
    small = sm.Tool("ball", 0.75, flute_length=4.0, shank_length=0.0, holder_radius=HOLDER, holder_length=20.0)
    job = sm.machine(pocket(), 0.0, [sm.Rough(rough, stepdown=2.0, allowance=0.3), sm.Finish(finish, scallop=0.05),
                                     sm.Rest(small)], verify=False)
    rest = job.operations[2]
    assert rest.name == "rest" and rest.report["holder"] is not None and rest.report["holder"].moves > 0
    prog = written(job, tmp_path)
    moves = [m for m in prog.moves if m.tool == 3]
    assert moves and not any(holder_hits(m.a, m.b, HOLDER, 4.0) for m in moves)


def test_verifier_finds_a_holder_too_low(short_job, tmp_path):
    """The short job's program judged as if the holder sat 2 mm lower on the tools (flutes
    of 2 mm): the moves whose holder cleared the block's top by a hair now stand 2 mm into
    it, and the verifier says so for each operation."""
    lower = [replace(op, tool=replace(op.tool, flute_length=2.0)) for op in short_job.operations]
    v = verify_job(replace(short_job, operations=tuple(lower)))
    held = [f for f in v.findings if f.what.startswith("holder")]
    assert len(held) == 2 and not any(f.ok for f in held)
    prog = written(short_job, tmp_path)
    for f, op in zip(held, short_job.operations):
        # the exact depth on the box, of the moves as written, with the lower holder
        exact = max(holder_depth(m.a, m.b, HOLDER, 2.0) for m in prog.moves if m.tool == op.tool.number)
        assert 1.0 < exact <= 2.0 + 1e-3  # the tips kept stand at z >= 1 where the holder overlaps
        # the verifier's probes grow the disc by half their spacing: as deep or a little deeper
        assert exact - 1e-3 <= f.worst <= exact + 0.05, (str(f), exact)
        assert f.where is not None and f.line > 0


def test_a_wall_is_cut_down_to_where_the_holder_lets_the_tool_go():
    """cam_part as ``python -m benchmarks cam`` machines it: ball r 3 with its holder
    (r 7.5) 24 mm above the tip.  Beside the part's x = 80 wall the holder passes over the
    mould's top: the part 23.7 high within its radius, the job's stock model 23.87 after
    the raster (its nodes see 0.17 of the raster's cusps).  The job held the holder the
    cusps (0.165) above the model, counting them twice, and left out the wall's lowest
    contours for y 22.5-34.5 (0.038 mm left on the table beside the wall, the contour
    again at the holder's reach cut the rest), while the verifier asked the wall of the
    tool with the holder the cusps above the part alone.  One reach rule for both
    (:func:`surfmod.cam.verify.body_stand`): the holder stands the cusps above the part
    and no lower than the stock the model holds, so the wall is cut down to the table and
    nothing is held."""
    part = Path(__file__).resolve().parent.parent / "step_samples" / "cam_part.step"
    job = sm.machine(str(part), 2.0, [sm.Rough(sm.Tool("flat", 5.0), stepdown=5.0, allowance=0.5),
                                      sm.Finish(sm.Tool("ball", 3.0), scallop=0.15)])
    walls = next(f for f in job.verification.findings if f.what.startswith("residual on walls"))
    assert walls.worst < 0.02 and job.verification.ok, "\n".join(job.verification.lines())
    fin = job.operations[1]
    assert fin.report["holder"] is None and "at_reach" not in fin.report["waterline"]
    # the wall's (x = 80 + r + margin) contours beside the mould go down to the table
    p = fin.motion.points
    at = p[(np.abs(p[:, 0] - 83.0079) < 1e-3) & (np.abs(p[:, 1] - 32.0) < 2.5)]
    assert at[:, 2].min() < 1e-6, np.unique(at[:, 2])


def test_a_rim_between_the_model_nodes_is_met():
    """The job's stock model samples the stock a cell apart: a holder whose rim passes
    between two nodes into a wall must still be met.  A flat r = 8 slot cut along y at
    x = 11.5 leaves a wall at x = 19.5; a holder of radius 6 over a tool at x = 13.6 reaches
    x = 19.59, 14.5 mm below the wall's top, while the model's nodes (cells of 1 mm) stand
    at x = 19 (cut) and 20 (beyond the rim)."""
    stock = StockModel(np.array([[0.0, 0.0, -10.0], [40.0, 40.0, 20.0]]), 1.0)
    slot = Motion(np.array([[11.5, -10.0, 0.0], [11.5, 50.0, 0.0]]), np.array([RAPID, FEED], np.int8))
    stock.sweep(slot, sm.Tool("flat", 8.0, flute_length=40.0))
    tool = sm.Tool("flat", 2.0, flute_length=5.0, shank_length=0.0, holder_radius=6.0, holder_length=20.0)
    far = np.array([[[0.0, 0.0, -100.0], [1.0, 0.0, -100.0], [0.0, 1.0, -100.0]]])  # no part near
    moves = Motion(np.array([[13.6, -10.0, 30.0], [13.6, -10.0, 0.5], [13.6, 50.0, 0.5], [13.6, 50.0, 30.0]]),
                   np.array([RAPID, RAPID, FEED, RAPID], np.int8))
    kept, _ = clear_body(moves, tool, stock, far, 0.0, 0.01, 30.0)
    assert len(kept.points) < len(moves.points) and not np.any(kept.kind == FEED)


def test_the_plunge_onto_a_move_after_a_gap_is_held_too():
    """After moves left out, the tool comes straight down onto the next move kept: where
    that move is not measured itself (of no length, or straight up), the plunge still is.
    On zoo's bracket the relink plunged 159 mm onto such moves, the holder 68 mm in the
    stock.  Here a block 20 high is uncut; every move of a tool whose holder stands 5 mm
    above its tip, at z = 0, buries the holder."""
    stock = StockModel(np.array([[0.0, 0.0, -10.0], [40.0, 40.0, 20.0]]), 1.0)
    tool = sm.Tool("flat", 2.0, flute_length=5.0, shank_length=0.0, holder_radius=6.0, holder_length=20.0)
    far = np.array([[[0.0, 0.0, -100.0], [1.0, 0.0, -100.0], [0.0, 1.0, -100.0]]])
    pts = [[20, 20, 30], [20, 20, 0], [25, 20, 0], [25, 20, 30], [30, 30, 30], [30, 30, 0], [30, 30, 0],
           [30, 30, 30]]
    kinds = [RAPID, FEED, FEED, RAPID, RAPID, RAPID, FEED, RAPID]
    kept, _ = clear_body(Motion(np.array(pts, float), np.array(kinds, np.int8)), tool, stock, far, 0.0, 0.01, 30.0)
    assert kept.points[:, 2].min() > 15.0, kept.points.tolist()


def test_a_holder_over_cusps_the_model_cannot_see_is_held():
    """The job's stock model is coarser than the finishing's passes: nodes a cell apart
    on the passes see the bottom, not the cusps between them.  A ball r = 2 rasters along y
    0.5 apart at z = 18 (the nodes, 1 apart, lie on passes); the cusps stand
    ``r - sqrt(r² - 0.25²)`` = 0.0157 high (the textbook cusp).  A plunge beside them
    brings the holder's bottom 0.006 into the cusps: the model alone sees 0.01 of clear air,
    the holder must clear the part under them (the passes' bottom) by the cusp (on zoo's
    flange-xy the finishing's holder passed 0.008 over the finished top, into its 0.033
    cusps)."""
    r, step, z = 2.0, 0.5, 18.0
    cusp = r - np.sqrt(r * r - (step / 2) ** 2)
    stock = StockModel(np.array([[0.0, 0.0, 0.0], [40.0, 40.0, 20.0]]), 1.0)
    ball = sm.Tool("ball", r, flute_length=10.0)
    xs = np.arange(0.0, 40.0 + step / 2, step)
    pts = np.array([[x, y, z] for k, x in enumerate(xs) for y in ((-5.0, 45.0) if k % 2 == 0 else (45.0, -5.0))])
    stock.sweep(Motion(pts, np.full(len(pts), FEED, np.int8)), ball)
    assert abs(float(stock.top[5:35, 5:35].max()) - z) < 1e-9  # the model is blind to the cusps
    tool = sm.Tool("ball", r, flute_length=5.0, shank_length=0.0, holder_radius=6.0, holder_length=20.0)
    plane = np.array([[[-10.0, -10.0, z], [60.0, -10.0, z], [-10.0, 60.0, z]],
                      [[60.0, -10.0, z], [60.0, 60.0, z], [-10.0, 60.0, z]]])  # the part the passes finished
    tip = z + cusp - 0.006 - 5.0  # the holder's bottom 0.006 below the cusps' tops
    plunge = Motion(np.array([[20.25, 20.0, 30.0], [20.25, 20.0, tip], [20.25, 20.0, 30.0]]),
                    np.array([RAPID, FEED, FEED], np.int8))
    kept, _ = clear_body(plunge, tool, stock, plane, 0.0, 0.001, 30.0)
    assert kept.points[:, 2].min() == tip  # blind: kept
    kept, _ = clear_body(plunge, tool, stock, plane, 0.0, 0.001, 30.0, cusp=cusp)
    assert kept.points[:, 2].min() > tip + 1.0, kept.points.tolist()


def test_the_holder_clears_the_cusps_a_stepover_leaves_on_walls():
    """A bull nose 3/1 finishing at a stepover of 2.5 leaves no scallop on flat ground, but
    its contours 2.5 apart along a wall leave cusps up to 0.525 high (the wall check's
    ``Cutter.wall_cusp`` on a wall of ``DEXEL_SLOPE``).  The holder is held above the part
    by that same cusp: a plunge whose holder's bottom comes 0.3 over the part is left out
    (the old rule, scallop + tolerance = 0.03, kept it: the holder in the cusps)."""
    bull = sm.Tool("bull", 3.0, 1.0)
    finishing = SimpleNamespace(name="finishing", tool=bull,
                                report={"scallop": 0.0, "tolerance": 0.03, "waterline": {"spacing": 2.5}})
    wall_cusp = bull.cutter.wall_cusp(2.5, wall_dexels.DEXEL_SLOPE)
    assert 0.52 < wall_cusp < 0.53
    cusp = cusp_clearance([finishing])
    assert cusp == pytest.approx(wall_cusp + 0.03, rel=1e-15)
    z = 18.0
    stock = StockModel(np.array([[0.0, 0.0, 0.0], [40.0, 40.0, 20.0]]), 1.0)
    tool = sm.Tool("bull", 3.0, 1.0, flute_length=5.0, shank_length=0.0, holder_radius=8.0, holder_length=20.0)
    plane = np.array([[[-10.0, -10.0, z], [60.0, -10.0, z], [-10.0, 60.0, z]],
                      [[60.0, -10.0, z], [60.0, 60.0, z], [-10.0, 60.0, z]]])
    tip = z + 0.3 - 5.0  # the holder's bottom 0.3 over the part: below the wall cusps' 0.525
    stock.sweep(Motion(np.array([[20.0, -5.0, tip], [20.0, 45.0, tip]]), np.array([RAPID, FEED], np.int8)),
                sm.Tool("flat", 10.0, flute_length=40.0))  # the stock round it already cut
    plunge = Motion(np.array([[20.0, 20.0, 30.0], [20.0, 20.0, tip], [20.0, 20.0, 30.0]]),
                    np.array([RAPID, FEED, FEED], np.int8))
    kept, _ = clear_body(plunge, tool, stock, plane, 0.0, 0.001, 30.0, cusp=0.03)
    assert kept.points[:, 2].min() == tip  # the old clearance: kept
    kept, _ = clear_body(plunge, tool, stock, plane, 0.0, 0.001, 30.0, cusp=cusp)
    assert kept.points[:, 2].min() > tip + 1.0, kept.points.tolist()


def test_a_shank_beside_a_tall_wall_keeps_off_the_roughings_skin():
    """A boss 30 mm tall on a plate, a ball r 2 with flutes 6 long and a shank as wide as
    the ball: the finishing's raster comes down beside the boss while the roughing's
    0.5 mm skin still stands on its walls (the contours cut them after it), and the shank
    would rub it (the verifier found it 24.5 mm deep).  The job's stock model (0.5 mm
    cells) stands no node in that skin: a move beside a wall, within the skin, holds
    every disc a cell wider against the stock above the part.  It leaves those moves out
    and says so; the contours and the repair's cross passes finish the rest, and every
    promise holds."""
    part = (bd.Box(40, 40, 4, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
            + bd.Pos(0, 0, 4) * bd.Box(12, 12, 30, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)))
    ball = sm.Tool("ball", 2.0, flute_length=6.0, shank_radius=2.0, shank_length=40.0, holder_radius=6.0,
                   holder_length=20.0)
    job = sm.machine(part, 1.0, [sm.Rough(sm.Tool("flat", 3.0, flute_length=40.0), stepdown=3.0, allowance=0.5),
                                 sm.Finish(ball, scallop=0.1)])
    body = next(f for f in job.verification.findings if f.what.startswith("holder and shank, finishing"))
    assert body.ok and job.verification.ok, "\n".join(job.verification.lines())
    held = job.operations[1].report["holder"]
    assert held is not None and held.moves > 0 and held.area > 0
    # the roughing, a flat r 3 kept 0.5 mm off the walls, is not held by its own skin
    assert job.operations[0].report["holder"] is None


def test_the_rest_contours_again_at_the_holders_reach():
    """A 16 x 16 pocket 12 deep with sharp corners: the finishing's ball r 2.5 leaves them
    for a rest ball r 1 whose holder (r 3.5) stands 6 mm above its tip, so the holder keeps
    the corners' contours above the pocket's rim out below a tip of about 10.  As the
    finishing's, the rest operation contours those places again at the lowest height the
    holder allows there (one code path: ``job._held``), and every promise holds."""
    part = (bd.Box(30, 30, 16, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN))
            - bd.Pos(0, 0, 4) * bd.Box(16, 16, 20, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)))
    small = sm.Tool("ball", 1.0, flute_length=3.0, shank_length=3.0, holder_radius=3.5, holder_length=20.0)
    job = sm.machine(part, 0.0, [sm.Rough(sm.Tool("flat", 2.5, flute_length=30.0), stepdown=3.0, allowance=0.3),
                                 sm.Finish(sm.Tool("ball", 2.5, flute_length=30.0), scallop=0.08), sm.Rest(small)])
    assert job.verification.ok, "\n".join(job.verification.lines())
    rest = job.operations[2].report
    assert rest["holder"] is not None and rest["at_reach"] >= 1
