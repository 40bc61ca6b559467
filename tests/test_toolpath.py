"""Drop-cutter tool paths: closed forms, no gouge, OpenCAMLib cross-check, G-code."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import surfmod as sm

bd = pytest.importorskip("build123d")


def bumpy():
    net = np.zeros((5, 5, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:5, 0:5] * 5.0
    net[..., 2] = np.random.default_rng(0).random((5, 5)) * 4
    return sm.BezierSurface(net)


def test_plane_heights_and_scallop_stepover():
    s = sm.plane((0, 0, 1), (10, 0, 1), (0, 6, 1))
    tool = sm.Tool("ball", 2.0)
    tp = sm.toolpath(s, tool, scallop=0.05)
    nominal = 2 * math.sqrt(2 * 2 * 0.05 - 0.05**2)
    assert tool.stepover_for_scallop(0.05) == pytest.approx(nominal, rel=1e-15)
    assert tp.stepover <= nominal + 1e-12 and tp.scallop <= 0.05 + 1e-12
    assert np.abs(tp.points[:, 2] - 1).max() < 1e-12
    ys = np.unique(tp.points[tp.pass_index >= 0, 1])
    assert len(ys) == tp.n_passes and np.diff(ys).max() <= nominal + 1e-12
    # zig-zag: consecutive passes run in opposite directions, joined continuously
    first, second = (tp.points[tp.pass_index == k] for k in (0, 1))
    assert first[0, 0] < first[-1, 0] and second[0, 0] > second[-1, 0]
    assert np.linalg.norm(np.diff(tp.points[:, :2], axis=0), axis=1).max() <= tp.step + 1e-12


def test_ball_and_flat_on_sphere_closed_forms():
    R, r = 10.0, 2.0
    ang = np.linspace(0, 2 * np.pi, 7)
    d = np.linspace(0, 5, 7)
    xy = np.column_stack([d * np.cos(ang), d * np.sin(ang)])
    from surfmod.uses.toolpath import drop_cutter

    z, cc = drop_cutter(bd.Sphere(R), sm.Tool("ball", r), xy)
    assert np.abs(z - (np.sqrt((R + r) ** 2 - d**2) - r)).max() < 1e-10
    assert np.abs(np.linalg.norm(cc, axis=1) - R).max() < 1e-12  # contacts on the sphere
    z, _ = drop_cutter(bd.Sphere(R), sm.Tool("flat", r), xy)
    expect = np.where(d <= r, R, np.sqrt(R**2 - np.maximum(d - r, 0) ** 2))
    assert np.abs(z - expect).max() < 1e-9


@pytest.mark.parametrize("kind", ["ball", "flat"])
def test_no_gouge_on_spline_surface(kind):
    tp = sm.toolpath(bumpy(), sm.Tool(kind, 2.0), stepover=2.5, step=1.0)
    assert tp.gouge < 1e-9
    assert np.isfinite(tp.contacts).all()


def test_opencamlib_cross_check(tmp_path):
    try:
        import opencamlib  # noqa: F401
    except Exception as exc:  # pragma: no cover
        pytest.skip(f"opencamlib not importable: {exc}")
    s = bumpy()
    tool = sm.Tool("ball", 2.0)
    tp = sm.toolpath(s, tool, stepover=2.0, step=1.0)
    stl = tmp_path / "s.stl"
    sm.export_stl(sm.mesh(s, 120, 120), stl, ascii=True)
    np.save(tmp_path / "cl.npy", tp.points[:, :2])
    # OpenCAMLib runs in its own process (its objects must outlive the C++ calls)
    code = textwrap.dedent(f"""
        import numpy as np, opencamlib as ocl
        surf = ocl.STLSurf(); ocl.STLReader({str(stl)!r}, surf)
        cutter = ocl.BallCutter({tool.diameter}, 20.0)
        bdc = ocl.BatchDropCutter(); bdc.setSTL(surf); bdc.setCutter(cutter)
        for x, y in np.load({str(tmp_path / 'cl.npy')!r}):
            bdc.appendPoint(ocl.CLPoint(float(x), float(y), -100.0))
        bdc.run()
        np.save({str(tmp_path / 'z.npy')!r}, np.array([p.z for p in bdc.getCLPoints()]))
    """)
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
    z_ocl = np.load(tmp_path / "z.npy")
    # OCL drops onto the 120 x 120 grid triangulation; the gap is its chordal error
    assert np.abs(z_ocl - tp.points[:, 2]).max() < 1e-3 * tool.radius


def test_gcode_export(tmp_path):
    tp = sm.toolpath(bd.Box(10, 6, 2), sm.Tool("flat", 1.5), stepover=2.0, step=1.0, direction="y")
    assert np.abs(tp.points[:, 2] - 1).max() < 1e-12  # the box top at z = 1
    path = tmp_path / "p.nc"
    sm.export_gcode(tp, path, feed=800, safe_height=20)
    lines = path.read_text().splitlines()
    assert lines[:6] == ["%", lines[1], lines[2], "G21 (millimetres)", "G90 (absolute)", "G17 (XY plane)"]
    assert lines[6] == "G0 Z20.0000" and lines[-2:] == ["M2", "%"] and lines[-3] == "G0 Z20.0000"
    moves = [ln for ln in lines if ln.startswith("G1 X")]
    assert moves[0].endswith("F800") and len(moves) == len(tp.points) - 1
    xyz = np.array([[float(w[1:]) for w in ln.split()[1:4]] for ln in moves])
    assert np.abs(xyz - tp.points[1:]).max() <= 5e-5
    assert "drop-cutter" in tp.to_gcode() and str(tp).startswith("toolpath: flat")


@pytest.mark.parametrize("make, arg", [
    (lambda: sm.Tool("ball", 0), "radius"),
    (lambda: sm.Tool("ball", -1), "radius"),
    (lambda: sm.Tool("bull", 1), "kind"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=2.5), "stepover"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), scallop=1.0), "scallop"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("flat", 1), scallop=0.1), "scallop"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, scallop=0.1), "stepover"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1)), "stepover"),
    (lambda: sm.toolpath(bumpy(), "ball", stepover=1), "tool"),
    (lambda: sm.toolpath(bumpy(), sm.Tool("ball", 1), stepover=1, direction="z"), "direction"),
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


def test_solid_top_faces_fillet_closed_form(tmp_path):
    """Ball over a filleted block from STEP: on the fillet (axis x = 8, z = 0.5, radius 2)
    the tip height is 0.5 + sqrt((2 + r)^2 - (x - 8)^2) - r; on the top face it is 2.5."""
    from surfmod.uses.toolpath import drop_cutter

    solid = bd.fillet(bd.Box(20, 20, 5).edges().group_by(bd.Axis.Z)[-1], radius=2)
    path = tmp_path / "block.step"
    sm.export_step(solid, path)
    r = 1.0
    x = np.array([0.0, 5.0, 8.0, 8.5, 9.0, 9.5])
    z, cc = drop_cutter(str(path), sm.Tool("ball", r), np.column_stack([x, np.zeros_like(x)]))
    expect = np.where(x <= 8, 2.5, 0.5 + np.sqrt((2 + r) ** 2 - np.maximum(x - 8, 0) ** 2) - r)
    assert np.abs(z - expect).max() < 1e-9
    tp = sm.toolpath(str(path), sm.Tool("ball", r), stepover=1.5, step=1.0)
    assert tp.gouge < 1e-9 and tp.points[:, 2].max() == pytest.approx(2.5, abs=1e-12)
