"""Drop-cutter tool paths: closed forms, every move gouge-free by an exact OCCT check,
OpenCAMLib cross-check on a real part, G-code, refusal of paths that would gouge."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import build123d as bd
import numpy as np
import pytest
import toolpath_reference
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
from OCP.Extrema import Extrema_ExtFlag_MIN
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
from toolpath_reference import ball_clearance, flat_cuts, gcode_positions

import surfmod as sm
from surfmod.cli import main as cli_main
from surfmod.cam.drop_cutter import part_triangles
from surfmod.cam import toolpath as toolpath_module
from surfmod.cam import toolpath_moves
from surfmod.cam.cutters import CUTTERS, Ball, Flat
from surfmod.cam.drop_cutter import TriangleGrid, drop
from surfmod.inputs import to_shape
from surfmod.cam.toolpath import drop_cutter

CORPUS_PART = "trimesh_featuretype.STEP"
# G-code writes 4 decimals: x, y rounded to nearest (a wall may come 5e-5·√2 closer)
ROUNDING = 1e-4


def bumpy():
    net = np.zeros((5, 5, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:5, 0:5] * 5.0
    net[..., 2] = np.random.default_rng(0).random((5, 5)) * 4
    return sm.BezierSurface(net)


def stepped_block():
    """A 40 x 30 x 5 block with a 12 x 10 x 8 boss and a 10 mm round pocket: vertical
    walls that straight moves between drop-cutter points would cut."""
    block = bd.Box(40, 30, 5) + bd.Pos(6, 4, 6.5) * bd.Box(12, 10, 8)
    return block - bd.Pos(-10, -5, 2.5) * bd.Cylinder(5, 4)


def worst_cut(shape, points, radius, top):
    """Deepest cut of a ball-end path, by the exact swept-ribbon distance."""
    return radius - ball_clearance(to_shape(shape), np.asarray(points), radius, top)


def test_plane_heights_and_scallop_stepover():
    s = sm.plane((0, 0, 1), (10, 0, 1), (0, 6, 1))
    tool = sm.Tool("ball", 2.0)
    tp = sm.toolpath(s, tool, scallop=0.05)
    nominal = 2 * math.sqrt(2 * 2 * 0.05 - 0.05**2)
    assert tool.stepover_for_scallop(0.05) == pytest.approx(nominal, rel=1e-15)
    assert tp.stepover <= nominal + 1e-12 and tp.scallop <= 0.05 + 1e-12
    assert tp.tolerance == pytest.approx(0.05 / 10, rel=1e-12)  # a tenth of the scallop asked for
    assert np.abs(tp.points[:, 2] - 1).max() < 1e-12  # plane nodes are exact: the tip rides on z = 1
    ys = np.unique(tp.points[tp.pass_index >= 0, 1])
    assert len(ys) == tp.n_passes and np.diff(ys).max() <= nominal + 1e-12
    # zig-zag: consecutive passes run in opposite directions, joined continuously
    first, second = (tp.points[tp.pass_index == k] for k in (0, 1))
    assert first[0, 0] < first[-1, 0] and second[0, 0] > second[-1, 0]
    assert np.linalg.norm(np.diff(tp.points[:, :2], axis=0), axis=1).max() <= tp.step + 1e-12


def test_ball_and_flat_on_sphere_closed_forms():
    """Heights on a sphere: ball sqrt((R + r)² − d²) − r, flat R or sqrt(R² − (d − r)²),
    within the mesh tolerance asked for."""
    R, r, tol = 10.0, 2.0, 5e-3
    ang = np.linspace(0, 2 * np.pi, 7)
    d = np.linspace(0, 5, 7)
    xy = np.column_stack([d * np.cos(ang), d * np.sin(ang)])
    z, cc = drop_cutter(bd.Sphere(R), sm.Tool("ball", r), xy, tolerance=tol)
    assert np.abs(z - (np.sqrt((R + r) ** 2 - d**2) - r)).max() < tol
    assert np.abs(np.linalg.norm(cc, axis=1) - R).max() < tol  # contacts on the sphere
    z, _ = drop_cutter(bd.Sphere(R), sm.Tool("flat", r), xy, tolerance=tol)
    expect = np.where(d <= r, R, np.sqrt(R**2 - np.maximum(d - r, 0) ** 2))
    assert np.abs(z - expect).max() < tol


def test_triangle_features_closed_forms():
    """One triangle, exact: facet, edge and vertex contacts of ball and flat end mills."""
    tri = np.array([[[0, 0, 0], [10, 0, 0], [0, 10, 10]]], float)  # plane z = y
    grid = TriangleGrid(tri, 1.0)
    q = np.array([[3.0, 3.0], [5.0, -0.9], [-0.6, -0.8]])
    ball = drop(grid, Ball(1.0), q)
    # facet: centre r along the normal (0, -1, 1)/√2: tip = y + r√2 − r; at y = -0.9 the
    # facet contact would lie outside, the level edge y = z = 0 holds the ball:
    # tip = sqrt(r² − 0.9²) − r; vertex at the origin, d = 1: tip = −r
    assert ball == pytest.approx([3 + math.sqrt(2) - 1, math.sqrt(1 - 0.81) - 1, -1.0], abs=1e-14)
    flat = drop(grid, Flat(1.0), q)
    # flat: the rim point uphill (y + r) on the facet; at (-0.6, -0.8) only the vertex at
    # distance exactly r touches
    assert flat == pytest.approx([4.0, 0.1, 0.0], abs=1e-14)


def test_grid_cell_lists_run_from_the_highest_top_down():
    """The grid's cell lists, placed by a compiled counting sort, are the ones a sort of
    every (cell, triangle) entry by cell, then falling top, then triangle makes: on
    random triangles with many equal tops (the first triangle of equal tops first)."""
    rng = np.random.default_rng(5)
    # triangles up to 8 mm across over a 40 mm square, overlapping many cells and each other
    tri = rng.uniform(0, 40, (3000, 1, 3)) + rng.uniform(-4, 4, (3000, 3, 3))
    tri[:, :, 2] = np.round(tri[:, :, 2] / 8)  # tops of a few values: most lists hold ties
    for radius in (0.7, 3.0, 11.0):
        grid = TriangleGrid(tri, radius)
        i0 = np.floor((grid.lo - grid.origin) / grid.cell).astype(np.int64)
        i1 = np.floor((grid.hi - grid.origin) / grid.cell).astype(np.int64)
        entries = [(ix * grid.shape[1] + iy, -grid.top[t], t) for t in range(len(tri))
                   for ix in range(i0[t, 0], i1[t, 0] + 1) for iy in range(i0[t, 1], i1[t, 1] + 1)]
        cells, _, tris = np.array(sorted(entries)).T
        assert np.array_equal(grid._cells, cells) and np.array_equal(grid.listed, tris)


def exhaustive_drop(grid, cutter, xy):
    """Every triangle of each location's list solved (no bound prunes any), the first
    of the highest heights winning: what the pruned, warm-started walk must equal."""
    from surfmod.cam.drop_cutter import _drop_triangle

    start, stop = grid.segments(xy)
    z, won, contact = np.full(len(xy), -np.inf), np.full(len(xy), -1), np.empty(3)
    touch = np.full((len(xy), 3), np.nan)
    for i, (qx, qy) in enumerate(xy):
        for ti in grid.listed[start[i]:stop[i]]:
            if np.all((grid.lo[ti] <= (qx, qy)) & ((qx, qy) <= grid.hi[ti])):
                h = _drop_triangle(cutter.code, qx, qy, grid.rows, ti, grid.lo[ti], grid.hi[ti], grid.top[ti],
                                   grid.radius, cutter.corner, -np.inf, contact)
                if h > z[i]:
                    z[i], won[i], touch[i] = h, ti, contact
    z[~np.isfinite(z)] = np.nan
    return z, won, touch


@pytest.mark.parametrize("kind", ["ball", "flat", "bull"])
def test_the_warm_started_drop_equals_the_exhaustive_search_bit_for_bit(kind):
    """Each location's walk starts from the previous location's triangle and prunes with
    bounds widened against rounding: heights and triangles equal, bit for bit, those of
    solving every triangle, on a real mesh (a contact passes its triangle's top by
    rounding there) and on random triangles with tied tops, in raster and random order."""
    tri_real, _ = part_triangles(to_shape(bumpy()), 0.01)
    rng = np.random.default_rng(7)
    tri_tied = rng.uniform(0, 20, (400, 3, 3))
    tri_tied[:, :, 2] = np.round(tri_tied[:, :, 2] / 5)  # flat triangles at four heights: ties everywhere
    # a tool large beside the triangles (the 280 mm mould's ball over its 1 mm facets): a
    # cell's bounds then fall far below the tops, and corners of the lists touch nothing
    for tri, r in ((tri_real, 1.5), (tri_real, 4.0), (tri_tied, 2.0)):
        cutter = CUTTERS[kind](r, r / 3) if kind == "bull" else CUTTERS[kind](r)
        grid = TriangleGrid(tri, r)
        (x0, y0), (x1, y1) = tri[:, :, :2].min(axis=(0, 1)), tri[:, :, :2].max(axis=(0, 1))
        gx, gy = np.meshgrid(np.linspace(x0 - r, x1 + r, 23), np.linspace(y0 - r, y1 + r, 19), indexing="ij")
        raster = np.c_[gx.ravel(), gy.ravel()]
        for xy in (raster, rng.permutation(raster)):
            z, touch, won = drop(grid, cutter, xy, contacts=True, triangles=True)
            z_all, won_all, touch_all = exhaustive_drop(grid, cutter, xy)
            assert np.array_equal(z, z_all, equal_nan=True), np.nanmax(np.abs(z - z_all))
            assert np.array_equal(won, won_all)
            assert np.array_equal(touch, touch_all, equal_nan=True)


def test_the_judges_culling_finds_what_the_whole_part_finds(monkeypatch):
    """The exact judges measure against the faces whose (u, v) cells' boxes come near and
    skip flat-end placements nearer to a measured one than its distance: on paths that cut
    the walls and the curved pocket, the same ball depth and the same flat-end moves as
    with every face of the part at every placement."""
    block = stepped_block()
    part = to_shape(block)
    xy, _, _ = toolpath_moves.raster((-16, -10), (-4, 0), 2.5, 1.25, "x")
    r, tol = 1.5, 0.05
    ball = np.column_stack([xy, drop_cutter(block, sm.Tool("ball", r), xy, tolerance=tol)[0]])
    flat = np.column_stack([xy, drop_cutter(block, sm.Tool("flat", r), xy, tolerance=tol)[0]])
    flat = np.vstack([flat, [[-14, -8, 9], [-9, -5, 0.3]]])  # and a long plunge into the pocket's floor
    culled = worst_cut(block, ball, r, 30.0), flat_cuts(part, flat, r, tol, 30.0)
    assert culled[0] > 2 * tol and len(culled[1]) > 4 and culled[1][-1] == len(flat) - 2

    every = toolpath_reference.face_boxes(part)[0]
    monkeypatch.setattr(toolpath_reference, "_near_strips", lambda boxes, *_: np.arange(len(boxes)))
    assert worst_cut(block, ball, r, 30.0) == culled[0]
    whole, rho, cut = toolpath_reference.compound(every), r - tol, []
    for i in range(len(flat) - 1):
        a, b = flat[i], flat[i + 1]
        n = int(max(np.ceil(np.linalg.norm(b[:2] - a[:2]) / (r / 20)),
                    np.ceil(abs(b[2] - a[2]) / (tol / 4)) if np.linalg.norm(b[:2] - a[:2]) > 0 else 0, 1))
        for t in np.linspace(0.0, 1.0, n + 1):
            p = a + t * (b - a)
            axis = gp_Ax2(gp_Pnt(float(p[0]), float(p[1]), float(p[2] + tol)), gp_Dir(0, 0, 1))
            cutter = BRepPrimAPI_MakeCylinder(axis, rho, 30.0 - p[2] - tol).Shape()
            if BRepExtrema_DistShapeShape(cutter, whole, Extrema_ExtFlag_MIN).Value() <= 1e-9:
                cut.append(i)
                break
    assert cut == culled[1]


@pytest.mark.parametrize("kind", ["ball", "flat"])
def test_no_gouge_on_spline_surface(kind):
    tp = sm.toolpath(bumpy(), sm.Tool(kind, 2.0), stepover=2.5, step=1.0)
    assert tp.gouge + tp.deflection <= tp.tolerance
    if kind == "ball":
        top = tp.points[:, 2].max() + 10
        assert worst_cut(bumpy(), tp.points, 2.0, top) <= tp.tolerance


def test_walls_every_move_checked_exactly():
    """Raw drop-cutter points joined by straight moves cut the boss and pocket walls by
    tenths of a millimetre (the exact check sees it); the refined path cuts nowhere deeper than the
    tolerance, by the same exact check."""
    block, r = stepped_block(), 1.5
    tp = sm.toolpath(block, sm.Tool("ball", r), scallop=0.05)
    top = 30.0
    assert worst_cut(block, tp.points, r, top) <= tp.tolerance
    xy, _, _ = toolpath_moves.raster((-20, -15), (20, 15), tp.stepover, tp.step, "x")
    z, _ = drop_cutter(block, sm.Tool("ball", r), xy, tolerance=tp.tolerance)
    assert worst_cut(block, np.column_stack([xy, z]), r, top) > 40 * tp.tolerance  # deep into a wall


def test_the_drop_heights_known_under_the_points_spare_the_final_drops(monkeypatch):
    """The raster carries each point's drop height beside it, so the final check of every
    move does not drop at its ends again: on the stepped block (walls, staircases,
    refinement) the path is the one made with every end dropped again, bit for bit, with
    fewer locations dropped."""
    block, tool = stepped_block(), sm.Tool("ball", 1.5)
    gouge, checked = toolpath_module.move_gouge, []

    def known(height, points, *a):  # the column holds the drop height under every point
        z = height(points[:, :2])
        checked.append(np.array_equal(points[:, 3], np.where(np.isnan(z), -np.inf, z)))
        return gouge(height, points, *a)

    monkeypatch.setattr(toolpath_module, "move_gouge", known)
    sm.toolpath(block, tool, scallop=0.05)
    assert checked and all(checked)
    monkeypatch.setattr(toolpath_module, "move_gouge", gouge)
    dropped, drop_at = [], toolpath_module.drop
    monkeypatch.setattr(toolpath_module, "drop", lambda grid, cutter, xy, **kw: dropped.append(len(xy))
                        or drop_at(grid, cutter, xy, **kw))
    fast = sm.toolpath(block, tool, scallop=0.05)
    fast_drops = sum(dropped)
    dropped.clear()
    monkeypatch.setattr(toolpath_module, "move_gouge", lambda height, points, *a: gouge(height, points[:, :3], *a))
    again = sm.toolpath(block, tool, scallop=0.05)
    assert np.array_equal(fast.points, again.points) and np.array_equal(fast.contacts, again.contacts)
    assert (fast.gouge, fast.lifted) == (again.gouge, again.lifted)
    assert fast_drops + len(fast.points) <= sum(dropped)


def test_flat_end_walls_exact(tmp_path):
    """Flat end + shank along every move of a wall part, by shrunken OCCT cylinders."""
    block = bd.Box(20, 16, 4) + bd.Pos(2, 1, 4) * bd.Box(6, 5, 4)
    r = 2.0
    tp = sm.toolpath(block, sm.Tool("flat", r), stepover=3.0, step=1.5, tolerance=0.02)
    assert flat_cuts(to_shape(block), tp.points, r, tp.tolerance, 20.0) == []
    # the same locations joined without refinement cut the boss
    xy, _, _ = toolpath_moves.raster((-10, -8), (10, 8), 3.0, 1.5, "x")
    z, _ = drop_cutter(block, sm.Tool("flat", r), xy, tolerance=0.02)
    assert flat_cuts(to_shape(block), np.column_stack([xy, z]), r, 0.02, 20.0) != []


@pytest.mark.parametrize("kind", ["ball", "flat"])
def test_opencamlib_cross_check_on_corpus_part(corpus_dir, tmp_path, kind):
    """Cutter-location heights equal OpenCAMLib's BatchDropCutter on the same triangles
    (written to STL in float32, which both then read exactly)."""
    pytest.importorskip("opencamlib", reason="OpenCAMLib is the bench extra (pip install -e '.[bench]')")
    shape = to_shape(corpus_dir / CORPUS_PART)
    tri, _ = part_triangles(shape, 0.02)
    tri = tri.astype(np.float32).astype(float)
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    tri = tri[area > 1e-9]  # rounding to float32 can flatten slivers; OCL rejects them
    r = 3.0
    lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
    xy = lo[:2] + np.random.default_rng(1).random((1500, 2)) * (hi - lo)[:2]
    z = drop(TriangleGrid(tri, r), CUTTERS[kind](r), xy)
    stl = tmp_path / "part.stl"
    facets = "".join("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x!r} {y!r} {w!r}\n" for x, y, w in t.tolist())
                     + "endloop\nendfacet\n" for t in tri.astype(np.float32))
    stl.write_text(f"solid part\n{facets}endsolid part\n")
    np.save(tmp_path / "xy.npy", xy)
    cutter = f"BallCutter({2 * r}, 500.0)" if kind == "ball" else f"CylCutter({2 * r}, 500.0)"
    # OpenCAMLib runs in its own process (its objects must outlive the C++ calls)
    code = textwrap.dedent(f"""
        import numpy as np, opencamlib as ocl
        surf = ocl.STLSurf(); ocl.STLReader({str(stl)!r}, surf)
        cutter = ocl.{cutter}
        bdc = ocl.BatchDropCutter(); bdc.setSTL(surf); bdc.setCutter(cutter)
        for x, y in np.load({str(tmp_path / 'xy.npy')!r}):
            bdc.appendPoint(ocl.CLPoint(float(x), float(y), {float(lo[2]) - 100.0}))
        bdc.run()
        np.save({str(tmp_path / 'z.npy')!r}, np.array([p.z for p in bdc.getCLPoints()]))
    """)
    subprocess.run([sys.executable, "-c", code], check=True, timeout=300)
    z_ocl = np.load(tmp_path / "z.npy")
    miss = np.isnan(z)  # nothing within reach (holes, outside): OCL leaves its start height
    assert miss.mean() < 0.2 and np.all(z_ocl[miss] == float(lo[2]) - 100.0)
    assert np.abs(z_ocl[~miss] - z[~miss]).max() < 1e-9 * (hi - lo).max()


def test_gcode_export(tmp_path):
    tp = sm.toolpath(bd.Box(10, 6, 2), sm.Tool("flat", 1.5), stepover=2.0, step=1.0, direction="y")
    assert np.abs(tp.points[:, 2] - 1).max() < 1e-12  # the box top at z = 1
    path = tmp_path / "p.nc"
    sm.export_gcode(tp, path, feed=800, safe_height=20)
    lines = path.read_text().splitlines()
    assert lines[:7] == ["%", lines[1], lines[2], f"(every move checked: no cut deeper than {tp.tolerance:.4g} mm)",
                         "G21 (millimetres)", "G90 (absolute)", "G17 (XY plane)"]
    assert lines[7] == "G0 Z20.0000" and lines[-2:] == ["M2", "%"] and lines[-3] == "G0 Z20.0000"
    moves = [ln for ln in lines if ln.startswith("G1 X")]
    assert moves[0].endswith("F800") and len(moves) == len(tp.points) - 1
    xyz = np.array([[float(w[1:]) for w in ln.split()[1:4]] for ln in moves])
    assert np.abs(xyz[:, :2] - tp.points[1:, :2]).max() <= 5e-5
    # heights are rounded up, never down
    assert np.all(xyz[:, 2] >= tp.points[1:, 2] - 1e-12) and np.all(xyz[:, 2] - tp.points[1:, 2] < 1e-4)
    assert "drop-cutter" in tp.to_gcode() and str(tp).startswith("toolpath: flat")


def test_export_gcode_takes_a_toolpath_not_its_look_alike(tmp_path):
    """The writer checks the type (the import cycle that made it guess from attributes is
    gone): an object with a Toolpath's fields is refused naming ``toolpath``, no file made."""
    from types import SimpleNamespace

    tp = sm.toolpath(sm.plane((0, 0, 0), (4, 0, 0), (0, 4, 0)), sm.Tool("flat", 1.0), stepover=1.5)
    look_alike = SimpleNamespace(**{k: getattr(tp, k) for k in ("points", "tool", "stepover", "scallop", "tolerance")})
    path = tmp_path / "p.nc"
    with pytest.raises(sm.SurfmodError, match="^toolpath: expected a surfmod Toolpath, got SimpleNamespace"):
        sm.export_gcode(look_alike, path)
    assert not path.exists()
    sm.export_gcode(tp, path)
    assert path.read_text() == tp.to_gcode()


@pytest.mark.parametrize("make, arg", [
    (lambda: sm.Tool("ball", 0), "radius"),
    (lambda: sm.Tool("ball", -1), "radius"),
    (lambda: sm.Tool("cone", 1), "kind"), (lambda: sm.Tool("bull", 1), "corner_radius"), (lambda: sm.Tool("bull", 1, 1), "corner_radius"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=2.5), "stepover"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), scallop=1.0), "scallop"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("flat", 1), scallop=0.1), "scallop"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, scallop=0.1), "stepover"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1)), "stepover"),
    (lambda: sm.toolpath(bumpy(), "ball", stepover=1), "tool"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, direction="z"), "direction"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, tolerance=0), "tolerance"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, bounds=((1, 1), (0, 0))), "bounds"),
])
def test_bad_input(make, arg):
    with pytest.raises(sm.SurfmodError, match=arg):
        make()


def test_bad_gcode_export_leaves_no_file(tmp_path):
    tp = sm.toolpath(sm.plane((0, 0, 0), (4, 0, 0), (0, 4, 0)), sm.Tool("flat", 1.0), stepover=1.5)
    with pytest.raises(sm.SurfmodError, match="safe_height"):
        sm.export_gcode(tp, tmp_path / "a.nc", safe_height=-1)
    with pytest.raises(sm.SurfmodError, match="feed"):
        sm.export_gcode(tp, tmp_path / "a.nc", feed=0)
    with pytest.raises(sm.SurfmodError, match="path"):
        sm.export_gcode(tp, tmp_path / "a.txt")
    with pytest.raises(sm.SurfmodError, match="toolpath"):
        sm.export_gcode("G0", tmp_path / "a.nc")
    assert list(tmp_path.iterdir()) == []


def test_path_that_still_gouges_is_an_error(tmp_path, monkeypatch, capsys):
    """With refinement cut short, the walls cannot be cleared: the API raises, the CLI
    prints one line, exits 1 and writes no file."""
    monkeypatch.setattr(toolpath_moves, "REFINE_ROUNDS", 1)
    with pytest.raises(sm.SurfmodError, match="no safe path"):
        sm.toolpath(stepped_block(), sm.Tool("ball", 1.5), scallop=0.05)
    step = tmp_path / "block.step"
    sm.export_step(stepped_block(), step)
    out = tmp_path / "p.nc"
    code = cli_main(["toolpath", str(step), "--radius", "1.5", "--scallop", "0.05", "--out", str(out),
                        "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and not out.exists()
    assert len(err) == 1 and err[0].startswith("surfmod toolpath: error:") and "no safe path" in err[0]


def test_tiny_tolerance_and_huge_work_are_refused_before_the_work(tmp_path, monkeypatch, capsys):
    """A tolerance below the part's floor or whose mesh would be too large is refused
    before BRepMesh runs; drop-cutter work above ``max_work`` is refused from the raster
    on the mesh before the first drop, and again before any later round would pass the
    cap (the CLI: one line, exit 1, no file)."""
    sphere = bd.Sphere(10.0)
    tool = sm.Tool("ball", 1.0)

    def no_meshing(*args, **kwargs):
        raise AssertionError("BRepMesh ran before the refusal")

    monkeypatch.setattr(toolpath_module, "part_triangles", no_meshing)
    monkeypatch.setattr(toolpath_module, "MAX_TRIANGLES", 100_000)  # the sphere at 1e-4: ~600,000 estimated
    for tol, why in ((5e-324, "below the floor"), (1e-14, "below the floor"), (1e-5, "BRepMesh's time"),
                     (1e-4, "triangles, above the limit")):
        with pytest.raises(sm.SurfmodError, match=f"^tolerance: .*{why}"):
            sm.toolpath(sphere, tool, stepover=1.0, tolerance=tol)
    monkeypatch.undo()
    drops = []
    monkeypatch.setattr(toolpath_module, "drop", lambda *a, **k: drops.append(1) or drop(*a, **k))
    with pytest.raises(sm.SurfmodError, match=r"^max_work: the drop-cutter over [\d,]+ locations"):
        sm.toolpath(sphere, tool, stepover=1.0, max_work=100_000)
    assert drops == []  # refused from the estimate: nothing dropped
    # a cap above the estimate but below what the refinement needs: refused between rounds
    calls = []
    original = toolpath_module.WorkMeter.charge

    def charge(self, work, what):
        calls.append(self.used + work)
        return original(self, work, what)

    monkeypatch.setattr(toolpath_module.WorkMeter, "charge", charge)
    tp = sm.toolpath(sphere, tool, stepover=1.0)
    cap = (calls[0] * toolpath_module.NOMINAL_DROPS + calls[-1]) // 2
    assert calls[0] * toolpath_module.NOMINAL_DROPS < cap < calls[-1] and tp.gouge + tp.deflection <= tp.tolerance
    calls.clear()
    with pytest.raises(sm.SurfmodError, match=r"^max_work: the drop-cutter \(.*after [\d,]+ triangle tests\)"):
        sm.toolpath(sphere, tool, stepover=1.0, max_work=cap)
    assert max(calls[:-1]) <= cap < calls[-1]  # the refused round was charged, not dropped
    step = tmp_path / "sphere.step"
    sm.export_step(sphere, step)
    out = tmp_path / "p.nc"
    code = cli_main(["toolpath", str(step), "--radius", "1", "--stepover", "1", "--tolerance", "1e-5",
                     "--out", str(out), "--no-progress"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and not out.exists() and len(err) == 1 and "tolerance:" in err[0]


def test_progress_bar_counts_the_drop_cutter_work(monkeypatch):
    """The bar's total is the estimate from the raster, its count every triangle test
    charged (so it moves in every round), and it ends full."""
    seen = []
    original = toolpath_module.WorkMeter.charge

    def charge(self, work, what):
        original(self, work, what)
        seen.append((self.bar.n, self.bar.total, self.used))

    monkeypatch.setattr(toolpath_module.WorkMeter, "charge", charge)
    sm.toolpath(bumpy(), sm.Tool("ball", 2.0), stepover=2.5, step=1.0, progress=True)
    counts = [n for n, _, _ in seen]
    assert len(seen) > 5 and counts == sorted(counts) and len(set(counts)) == len(counts)
    assert all(n == used and n <= total for n, total, used in seen)


def test_solid_top_faces_fillet_closed_form(tmp_path):
    """Ball over a filleted block from STEP: on the fillet (axis x = 8, z = 0.5, radius 2)
    the tip height is 0.5 + sqrt((2 + r)^2 - (x - 8)^2) - r; on the top face it is 2.5."""
    solid = bd.fillet(bd.Box(20, 20, 5).edges().group_by(bd.Axis.Z)[-1], radius=2)
    path = tmp_path / "block.step"
    sm.export_step(solid, path)
    r, tol = 1.0, 1e-3
    x = np.array([0.0, 5.0, 8.0, 8.5, 9.0, 9.5])
    z, _ = drop_cutter(str(path), sm.Tool("ball", r), np.column_stack([x, np.zeros_like(x)]), tolerance=tol)
    expect = np.where(x <= 8, 2.5, 0.5 + np.sqrt((2 + r) ** 2 - np.maximum(x - 8, 0) ** 2) - r)
    assert np.abs(z - expect).max() < tol
    tp = sm.toolpath(str(path), sm.Tool("ball", r), stepover=1.5, step=1.0)
    assert tp.points[:, 2].max() == pytest.approx(2.5, abs=1e-12)
    assert worst_cut(solid, tp.points, r, 10.0) <= tp.tolerance


@pytest.mark.corpus
def test_cli_on_a_corpus_part(corpus_dir, tmp_path, capsys):
    """The part the issue reported gouging 6.7 mm at r = 3: now exit 0, and the written
    G-code cuts nowhere deeper than scallop / 10 by the exact check.  About 12 CPU
    seconds, most of them the judge: in the corpus run; the default run judges the
    command's path the same way on a smaller part
    (``test_corpus_toolpath.py::test_one_corpus_toolpath_never_gouges``)."""
    part = corpus_dir / CORPUS_PART
    out = tmp_path / "p.nc"
    r, scallop = 3.0, 0.3
    code = cli_main(["toolpath", str(part), "--radius", str(r), "--scallop", str(scallop),
                        "--out", str(out), "--no-progress"])
    assert code == 0, capsys.readouterr().err
    moves = gcode_positions(out.read_text())
    depth = r - ball_clearance(to_shape(part), moves, r, moves[:, 2].max() + r)
    assert depth <= scallop / 10 + ROUNDING
