"""Rest machining (``sm.Rest``, ``surfmod machine --rest``): a pocket whose inner edges are
rounded tighter than the finishing ball.  The finishing leaves material in the fillets; the
rest ball cuts it there and only there.  Judged independently of the job's own stock
model: the tests' stock simulation (``tests/stock_sim.py``) on the program as LinuxCNC's
``rs274`` reads it (the tests' own G-code reader where rs274 is missing), and OCCT's exact
distance from the part to the volume the rest ball sweeps."""

from __future__ import annotations

import build123d as bd
import numpy as np
import pytest
from stock_sim import RS274, Cutter, Program, Stock, normal_residual, parse_canon, parse_gcode, part_height, \
    run_rs274, side_grids, simulate, vertex_normals, wall_left, wall_points
from toolpath_reference import ball_clearance

import surfmod as sm
import surfmod.cam.rest as cam_rest
from surfmod.cam.drop_cutter import part_triangles
from surfmod.cam.job import _after
from surfmod.cam.rest import _runs
from surfmod.cam.roughing import RAPID
from surfmod.cli import main
from surfmod.inputs import to_shape

#: the pocket: 14 x 14, 3 deep in a 30 x 30 x 8 block (top z = 4, floor z = 1), every
#: inner edge rounded by FILLET; the finishing ball's radius is twice that
FILLET, HALF, FLOOR = 1.0, 7.0, 1.0
ROUGH, FINISH, REST = sm.Tool("flat", 2.0), sm.Tool("ball", 2.0), sm.Tool("ball", 0.75)
SCALLOP = 0.05
ROUNDING = 1e-4  # the program's 4 decimals


def pocket():
    part = bd.Box(30, 30, 8) - bd.Pos(0, 0, 4 - 1.5) * bd.Box(2 * HALF, 2 * HALF, 3)
    inner = [e for e in part.edges()
             if e.center().Z < 4 - 1e-6 and abs(e.center().X) < HALF + 0.01 and abs(e.center().Y) < HALF + 0.01]
    return part.fillet(FILLET, inner)


@pytest.fixture(scope="module")
def job():
    return sm.machine(pocket(), 1.0, [sm.Rough(ROUGH, stepdown=1.5, allowance=0.3), sm.Finish(FINISH, scallop=SCALLOP),
                                      sm.Rest(REST)])


@pytest.fixture(scope="module")
def program(job, tmp_path_factory):
    """The program's moves as the controller runs them: rs274's canonical moves, or the
    tests' own reader of the text where rs274 is not installed."""
    path = tmp_path_factory.mktemp("rest") / "job.ngc"
    sm.export_gcode(job, path, post="linuxcnc")
    if RS274 is not None:
        return parse_canon(run_rs274(path)), path
    return parse_gcode(path.read_text()), path


def test_rest_report_and_verdict(job):
    rough, finish, rest = job.operations
    assert [op.name for op in job.operations] == ["roughing", "finishing", "rest"]
    assert [op.tool.number for op in job.operations] == [1, 2, 3]
    rep = rest.report
    assert rep["after"] == [0, 1] and rep["scallop"] == SCALLOP and rep["tolerance"] == pytest.approx(SCALLOP / 10)
    # the finishing ball (r = 2) leaves the r = 1 fillets along the four floor edges and
    # the corners: a band round the floor's rim, a few mm² per mm of its 56 mm length
    before, after = rep["before"], rep["left"]
    assert 30.0 < before["area"] < 150.0 and before["max"] > 0.3
    assert after["area"] <= 0.02 * before["area"] and after["max"] < 0.2
    assert rep["runs"] > 0 and rest.length > 0
    # the rest tool cut only over the pocket's rim band: its cutting moves lie within the
    # fillets grown by its radius and the band's width, never over the open top or the floor's middle
    cuts = rest.motion.points[rest.motion.kind != RAPID]
    xy = np.abs(cuts[:, :2]).max(axis=1)
    assert xy.max() < HALF + REST.radius + 1.5 and xy.min() > HALF - FILLET - 2 * FINISH.radius
    text = str(rest)
    assert "rest after operations 1, 2" in text and "mm^2" in text
    assert any(f.what.startswith("gouge, rest (tool 3)") and f.ok for f in job.verification.findings)
    assert any(f.what.startswith("residual after rest (tool 3") and f.ok for f in job.verification.findings)
    # the walls' judge (dexels along x and y) sees what the height field could not: rasters
    # alone climbing the pocket's concave vertical corners (r = 1) left 0.070 mm there
    # (limit 0.056); the rest's contours on its steep part leave 0.013
    assert rep["contours"] > 0 and rep["levels"] > 0 and "contours on" in text
    walls = next(f for f in job.verification.findings if f.what.startswith("residual on walls after rest (tool 3"))
    assert walls.ok and walls.worst <= walls.limit, walls
    assert job.verification.ok, str(job.verification)


def _left_area(top, surface, judged, h, bound):
    res = normal_residual(top, surface, h)
    return float(np.sum(judged & (np.nan_to_num(res, nan=-np.inf) > bound))) * h * h, res


def test_rest_in_the_tests_own_stock_simulation(job, program):
    """After finishing the fillets hold more than the scallop; after the rest tool almost
    nothing, and no move of any tool cuts into the part."""
    prog, _ = program
    h = 0.05
    box = np.array([[-HALF - 0.5, -HALF - 0.5, job.stock[0, 2]], [HALF + 0.5, HALF + 0.5, job.stock[1, 2]]])
    stock = Stock(box, h)
    tri, _ = part_triangles(to_shape(pocket()), 0.002)
    surface = part_height(tri, stock.x, stock.y)
    cutters = {1: Cutter("flat", ROUGH.radius), 2: Cutter("ball", FINISH.radius), 3: Cutter("ball", REST.radius)}
    # moves that come nowhere near the simulated box cut nothing there
    near = [m for m in prog.moves if np.all(np.minimum(m.a[:2], m.b[:2]) <= box[1, :2] + 2.0)
            and np.all(np.maximum(m.a[:2], m.b[:2]) >= box[0, :2] - 2.0)]
    first = simulate(Program([m for m in near if m.tool in (1, 2)]), cutters, stock, surface)
    gx, gy = np.gradient(surface, h)
    # nodes on the floor and the fillets up to 60° (the walls a height field cannot judge),
    # a cell clear of the part's vertical faces
    judged = np.degrees(np.arctan(np.hypot(gx, gy))) < 60.0
    bound = SCALLOP + SCALLOP / 10 + 0.01  # scallop, tolerance, the simulation's cells
    finished, res = _left_area(stock.top, surface, judged, h, bound)
    assert finished > 50.0 and np.nanmax(np.where(judged, res, np.nan)) > 0.3
    second = simulate(Program([m for m in near if m.tool == 3]), cutters, stock, surface)
    rested, res = _left_area(stock.top, surface, judged, h, bound)
    assert rested <= 0.1, (finished, rested)  # measured: 68.6 mm² before, 0.0175 after
    # what the job's own model reported before agrees with the simulation's measure
    assert job.operations[2].report["before"]["area"] == pytest.approx(finished, rel=0.15)
    tolerance = SCALLOP / 10
    assert max(first.gouge, second.gouge) <= tolerance + ROUNDING + 1e-6
    assert second.rapid_cut <= 1e-6 and second.cut_without_spindle == 0


def test_rest_holds_the_scallop_on_the_corner_walls(program):
    """The tests' own dexels along x and y (``stock_sim.SideDexels``) over two of the
    pocket's vertical corners (r = 1, the rest ball's 0.75 reaches every point of them),
    swept by every tool's feed moves: above the floor fillet at most the scallop, the
    tolerance and the lines' spacing is left normal to the wall, and nothing is cut into
    it.  The rest operation's rasters alone (before its contours) left 0.073 mm on these
    two corners; with the contours 0.013 is left."""
    prog, _ = program
    tri, _, (_, owner) = part_triangles(to_shape(pocket()), 0.002, face_index=True)
    normals = vertex_normals(tri, owner)
    cutters = {1: Cutter("flat", ROUGH.radius), 2: Cutter("ball", FINISH.radius), 3: Cutter("ball", REST.radius)}
    feeds = {t: [m for m in prog.moves if m.tool == t and not m.rapid] for t in cutters}
    h = 0.05  # the lines' spacing: a cusp's crest between contour levels ~0.5 mm apart is met within h²/(8 r)
    left = []
    for corner in ((-1, 1), (1, -1)):  # the corners the rasters left most on
        ends = np.sort(np.outer([HALF - 2 * FILLET, HALF + 0.5], corner), axis=0)
        box = np.c_[ends, [FLOOR + FILLET, 4.0]]
        sides = side_grids(box, h)
        for t, cutter in cutters.items():
            a, b = np.array([m.a for m in feeds[t]]), np.array([m.b for m in feeds[t]])
            near = (np.all(np.minimum(a, b)[:, :2] <= box[1, :2] + cutter.radius, axis=1)
                    & np.all(np.maximum(a, b)[:, :2] >= box[0, :2] - cutter.radius, axis=1))
            for dex in sides:
                dex.cut(cutter, a[near], b[near])
        for dex in sides:
            w = wall_points(tri, dex, steep=60.0, normals=normals)
            p = w.point
            # on the corner's arc (beyond the straight walls' ends), above the floor fillet, below the rim
            on = (np.all((p[:, :2] >= box[0, :2]) & (p[:, :2] <= box[1, :2]), axis=1)
                  & (np.abs(p[:, :2]).min(axis=1) > HALF - FILLET) & (p[:, 2] > FLOOR + FILLET + 0.02)
                  & (p[:, 2] < 4.0 - 0.02))
            left.append(wall_left(dex, w)[on])
    left = np.concatenate(left)
    assert len(left) > 1000
    tolerance = SCALLOP / 10
    assert left.min() >= -(tolerance + ROUNDING), f"a cut {-left.min():.4f} into a corner wall"
    assert left.max() <= SCALLOP + tolerance + 0.01, f"{left.max():.4f} left on a corner wall"  # measured 0.0128


def test_rest_moves_never_gouge_exact(job, program):
    """OCCT's exact distance from the part to the ribbons the rest ball's centre sweeps."""
    _, path = program
    lines = path.read_text().splitlines()
    start = lines.index("T3 M6")
    pts, pos = [], [np.nan] * 3
    for line in lines[start:]:
        if line.startswith(("G0", "G1")):
            for word in line.split()[1:]:
                if word[0] in "XYZ":
                    pos["XYZ".index(word[0])] = float(word[1:])
            if not np.isnan(pos).any():
                pts.append(list(pos))
    pts = np.array(pts)
    depth = REST.radius - ball_clearance(to_shape(pocket()), pts, REST.radius, float(pts[:, 2].max()) + REST.radius)
    assert depth <= SCALLOP / 10 + ROUNDING


@pytest.mark.skipif(RS274 is None, reason="rs274 (Debian package linuxcnc-uspace) is not installed")
def test_rest_program_runs_in_rs274(program):
    prog, _ = program
    assert prog.tool_changes == [1, 2, 3] and prog.ended
    assert [t for t, _ in prog.spindle_starts] == [1, 2, 3]
    assert not any(not m.rapid and not m.spindle for m in prog.moves)
    assert any(m.tool == 3 and not m.rapid for m in prog.moves)


def test_runs_joined_along_the_raster():
    pts = np.c_[np.arange(11.0), np.zeros((11, 2))]
    inside = np.array([0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1], bool)
    assert _runs(inside, pts, 2.5) == [(0, 7), (9, 11)]
    assert _runs(inside, pts, 0.5) == [(0, 4), (4, 7), (9, 11)]
    assert _runs(np.zeros(5, bool), pts[:5], 1.0) == []


def test_rest_contours_refused_before_any_above_their_cap(monkeypatch):
    """The contours' fiber-triangle pairs over every rest region are estimated before the
    first contour is made, and refused above the waterline's cap naming the scallop."""
    def made(*args, **kw):
        raise AssertionError("a contour was made before the estimate refused")

    monkeypatch.setattr(cam_rest, "MAX_PAIRS", 1000)
    monkeypatch.setattr(cam_rest, "contour_moves", made)
    with pytest.raises(sm.SurfmodError, match=r"^scallop: the rest's contours over 1 region\(s\).*limit 1e\+03"):
        sm.machine(pocket(), 1.0, [sm.Finish(FINISH, scallop=SCALLOP), sm.Rest(REST)], verify=False)


def test_rest_bad_input():
    block = bd.Box(10, 10, 3)
    with pytest.raises(sm.SurfmodError, match="^after"):
        sm.machine(block, 0.0, [sm.Rest(REST)])
    with pytest.raises(sm.SurfmodError, match="^after"):
        sm.machine(block, 0.0, [sm.Finish(FINISH, scallop=SCALLOP), sm.Rest(REST, after=3)], verify=False)
    with pytest.raises(sm.SurfmodError, match="^after"):
        sm.machine(block, 0.0, [sm.Finish(FINISH, scallop=SCALLOP), sm.Rest(REST, after=True)], verify=False)
    with pytest.raises(sm.SurfmodError, match="^scallop"):
        sm.machine(block, 1.0, [sm.Rough(ROUGH, allowance=0.3), sm.Rest(REST)], verify=False)
    with pytest.raises(sm.SurfmodError, match="^scallop"):
        sm.machine(block, 0.0, [sm.Finish(FINISH, scallop=SCALLOP), sm.Rest(REST, scallop=-1.0)], verify=False)


def test_after_names_earlier_operations():
    rough, finish = sm.Rough(ROUGH), sm.Finish(FINISH, scallop=SCALLOP)
    ops = [rough, finish]
    assert _after(sm.Rest(REST), 2, ops) == [0, 1]
    assert _after(sm.Rest(REST, after=finish), 2, ops) == [1]
    assert _after(sm.Rest(REST, after=[1, 0, 1]), 2, ops) == [0, 1]
    for bad in ([], -1, 2, sm.Finish(FINISH, scallop=SCALLOP), "finishing"):
        with pytest.raises(sm.SurfmodError, match="^after"):
            _after(sm.Rest(REST, after=bad), 2, ops)


def test_a_rest_tool_no_smaller_warns_and_cuts_nothing_on_open_ground():
    """A plain block: the finishing reaches all of it, so the rest operation (a larger
    ball: allowed, with a warning) finds nothing left and makes no move."""
    ops = [sm.Finish(sm.Tool("ball", 1.0), scallop=SCALLOP), sm.Rest(sm.Tool("ball", 1.5))]
    with pytest.warns(UserWarning, match="^rest: .* no smaller"):
        job = sm.machine(bd.Box(10, 10, 3), 0.0, ops)
    rep = job.operations[1].report
    assert rep["before"]["area"] == 0.0 and rep["left"]["area"] == 0.0 and len(job.operations[1].moves) == 0
    assert job.verification.ok, str(job.verification)


def test_cli_rest(tmp_path, capsys):
    part = tmp_path / "pocket.step"
    bd.export_step(pocket(), str(part))
    out = tmp_path / "job.ngc"
    args = ["machine", str(part), "--out", str(out), "--stock-margin", "1", "--rough", "flat:2", "--stepdown", "1.5",
            "--allowance", "0.3", "--finish", "ball:2", "--scallop", str(SCALLOP), "--no-progress"]
    assert main(args + ["--rest", "ball:0.75", "--no-verify"]) == 0
    printed = capsys.readouterr().out
    assert "rest: T3 ball end mill r=0.75" in printed and "rest after operations 1, 2: left more than" in printed
    text = out.read_text()
    assert [ln for ln in text.splitlines() if ln.endswith("M6")] == ["T1 M6", "T2 M6", "T3 M6"]
    for bad, word in (("ball:-1", "radius"), ("drill:1", "rest"), ("ball:0.04", "scallop")):
        out2 = tmp_path / f"bad_{word}.ngc"
        assert main(args[:3] + [str(out2)] + args[4:] + ["--rest", bad]) == 1
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and f"error: {word}" in err[0], err
        assert not out2.exists()
