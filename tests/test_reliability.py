"""One regression test per signature of the "Reliability" issue (numbers as there), plus
the reader process, the caps and atomic writes under SIGKILL."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import CORPUS
from test_occt_quirks import quirk_holds

import surfmod as sm
from surfmod import atomic, checks
from surfmod import inputs

ROOT = Path(__file__).resolve().parent.parent
SCREW = CORPUS / "occt_screw.step"
PLANE = sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0))
CLI = [sys.executable, "-c", "import sys; from surfmod.cli import main; sys.exit(main())"]


def without_line(src: Path, prefix: bytes, out: Path) -> Path:
    """``src`` with the line starting with ``prefix`` deleted."""
    lines = src.read_bytes().split(b"\n")
    kept = [line for line in lines if not line.startswith(prefix)]
    assert len(kept) == len(lines) - 1
    out.write_bytes(b"\n".join(kept))
    return out


# 1 -------------------------------------------------------------------------------------------
def test_1_parameters_that_do_not_broadcast():
    s = sm.sphere(2.0)
    with pytest.raises(sm.SurfmodError, match=r"^u, v: shapes \(2,\) and \(3,\) do not broadcast together$"):
        s.points(np.zeros(2), np.zeros(3))
    with pytest.raises(sm.SurfmodError, match=r"^u: expected numbers, got ndarray"):
        s.points(np.array([object(), 1.0], dtype=object), 0.5)
    with pytest.raises(sm.SurfmodError, match=r"^v: expected numbers, got str"):
        s.normals(0.5, "0.5")
    # empty in, empty out (NumPy's rule), for every evaluation
    assert s.points([], []).shape == (0, 3)
    assert s.derivatives(np.zeros((0, 2)), 0.1, 2).shape == (0, 2, 3, 3, 3)
    assert s.grid([], [0.1, 0.2]).shape == (0, 2, 3)
    assert s.curvatures(np.zeros(0), 0.0).k1.shape == (0,)
    assert sm.Line((0, 0, 0), (1, 0, 0)).points(np.zeros(0)).shape == (0, 3)


# 2 -------------------------------------------------------------------------------------------
HUGE = 10**400
LINE = sm.Line((1, 0, 0), (1, 0, 4))


@pytest.mark.parametrize("call, name", [
    (lambda: sm.sphere(HUGE), "radius"),
    (lambda: sm.ellipsoid(1, HUGE, 1), "ry"),
    (lambda: sm.torus(HUGE, 1), "major"),
    (lambda: sm.torus(3, -HUGE), "minor"),
    (lambda: sm.superellipsoid(1, 1, 1, HUGE, 1), "s1"),
    (lambda: sm.Circle((0, 0, 0), (0, 0, 1), HUGE), "radius"),
    (lambda: sm.Arc((0, 0, 0), (0, 0, 1), 1, 0, HUGE), "end_angle"),
    (lambda: sm.tabulated_cylinder(sm.Circle((0, 0, 0), (0, 0, 1), 1), (0, 0, 1), HUGE), "length"),
    (lambda: sm.revolution(LINE, (0, 0, 0), (0, 0, 1), HUGE), "angle"),
    (lambda: sm.sphere(1.0).rotated((0, 0, 0), (0, 0, 1), HUGE), "degrees"),
    (lambda: sm.sweep(sm.Line((-1, 0, 0), (1, 0, 0)), sm.Line((0, 0, 0), (0, 0, 5)), twist=HUGE), "twist"),
    (lambda: sm.sphere(1.0, center=(HUGE, 0, 0)), "center"),
    (lambda: sm.Line((0, 0, 0), (0, 0, 1)).points(HUGE), "t"),
])
def test_2_huge_integers(call, name):
    with pytest.raises(sm.SurfmodError, match=rf"^{name}: a number is too large \(limit 1e\+70\)$"):
        call()


def test_2_the_magnitude_limit_keeps_evaluation_finite():
    """1e70 is accepted and even curvature (fourth powers) evaluates without overflow;
    1e71 is refused."""
    s = sm.sphere(1e70)
    c = s.curvatures(0.3, 0.2)
    assert c.gaussian == pytest.approx(1e-140, rel=1e-12) and abs(c.mean) == pytest.approx(1e-70, rel=1e-12)
    np.testing.assert_allclose(np.linalg.norm(s.points(0.3, 0.2)), 1e70, rtol=1e-15)
    with pytest.raises(sm.SurfmodError, match=r"^radius: 1e\+71 exceeds the limit 1e\+70 in magnitude$"):
        sm.sphere(1e71)


# 3 -------------------------------------------------------------------------------------------
def test_3_derivative_orders():
    line = sm.Line((0, 0, 0), (1, 0, 0))
    with pytest.raises(sm.SurfmodError, match=r"^order: must be <= 20, got 100000000000000000000$"):
        line.derivatives(0.5, order=10**20)
    with pytest.raises(sm.SurfmodError, match=r"^order: must be <= 20, got 21$"):
        PLANE.grid_derivatives([0.5], [0.5], 21)
    with pytest.raises(sm.SurfmodError, match=r"^order: expected an integer"):
        line.derivatives(0.5, order=2.0)
    d = line.derivatives(0.5, order=checks.MAX_DERIVATIVE_ORDER)
    assert d.shape == (21, 3)
    np.testing.assert_array_equal(d[1], [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(d[2:], 0.0)


# 4 -------------------------------------------------------------------------------------------
def test_4_ragged_parameter_lists():
    with pytest.raises(sm.SurfmodError, match=r"^us: expected numbers, got list \(ragged nested lists\)$"):
        sm.sphere(2.0).grid([[0.1, 0.2], [0.3]], [0.5])
    with pytest.raises(sm.SurfmodError, match=r"^v: expected numbers, got list \(ragged nested lists\)$"):
        sm.sphere(2.0).points(0.1, [[0.1], [0.2, 0.3]])


# 5 -------------------------------------------------------------------------------------------
def test_5_a_file_that_crashes_occt_raises_and_the_reader_recovers(tmp_path):
    # deleting the 2-D point #169 makes OCCT's STEP reader dereference a null handle
    bad = without_line(SCREW, b"#169 = ", tmp_path / "screw-169.step")
    with pytest.raises(sm.DamagedFileError, match=r"^path: OCCT crashed reading .*screw-169\.step \(signal SIGSEGV\)"):
        sm.import_step(bad)
    # the next read starts a fresh worker and is exact
    good = sm.import_step(SCREW)
    assert len(good.faces()) == 10


def test_5_missing_point_reads_as_huge_coordinates(tmp_path):
    """A deleted CARTESIAN_POINT leaves OCCT's 1e100 placeholder in the shape."""
    bad = without_line(SCREW, b"#39 = CARTESIAN_POINT", tmp_path / "screw-39.step")
    with pytest.raises(sm.DamagedFileError, match=r"^path: .*screw-39\.step has coordinates up to 1e\+100, "
                                                  r"beyond the limit 1e\+09"):
        sm.import_step(bad)


def test_5_time_limit(tmp_path):
    with pytest.raises(sm.DamagedFileError, match=r"^path: reading .*linkrods\.step did not finish within 0\.01 s"):
        sm.import_step(CORPUS / "occt_linkrods.step", timeout=0.01)
    with pytest.raises(sm.SurfmodError, match=r"^timeout: must be a finite number > 0"):
        sm.import_step(SCREW, timeout=0)


def test_5_the_worker_is_reused_and_the_shape_is_exact():
    from surfmod.occ.step import read_step

    first = sm.import_step(SCREW)
    pid = inputs._READER.server.proc.pid
    second = sm.import_step(CORPUS / "cadquery_red_cube_blue_cylinder.step")
    assert inputs._READER.server.proc.pid == pid
    assert len(second.solids()) == 2
    # BinTools carries the geometry bit for bit: same vertices as an in-process read
    import build123d as bd

    direct = bd.Compound.cast(read_step(str(SCREW)))
    a = sorted(tuple(v) for v in first.vertices())
    b = sorted(tuple(v) for v in direct.vertices())
    assert a == b
    assert first.volume == pytest.approx(direct.volume, rel=1e-15)


def test_5_the_command_line_exits_1_with_one_line(tmp_path):
    bad = without_line(SCREW, b"#169 = ", tmp_path / "screw-169.step")
    out = subprocess.run([*CLI, "mass", str(bad), "--no-progress"],
                         check=False, capture_output=True, text=True, cwd=ROOT, timeout=300,
                         env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 1
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in out.stderr
    assert lines[0].startswith("surfmod mass: error: path: OCCT crashed reading") and "screw-169.step" in lines[0]


@pytest.mark.corpus
@pytest.mark.parametrize("command", ["check", "mesh", "mass", "section", "femesh", "toolpath"])
def test_5_every_command_reads_through_the_isolated_reader(command, tmp_path):
    bad = without_line(SCREW, b"#169 = ", tmp_path / "screw-169.step")
    extra = {
        "check": ["--no-progress"], "mesh": [], "mass": ["--no-progress"],
        "section": ["--origin", "0", "0", "0", "--normal", "0", "0", "1", "--out", str(tmp_path / "s.dxf")],
        "femesh": ["--size", "5", "--out", str(tmp_path / "f.msh")],
        "toolpath": ["--radius", "2", "--scallop", "0.05", "--out", str(tmp_path / "t.nc")],
    }[command]
    out = subprocess.run([*CLI, command, str(bad), *extra],
                         check=False, capture_output=True, text=True, cwd=ROOT, timeout=300,
                         env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert out.returncode == 1, out.stderr
    assert "Traceback" not in out.stderr
    assert "OCCT crashed reading" in out.stderr + out.stdout and "screw-169.step" in out.stderr + out.stdout


# 6 -------------------------------------------------------------------------------------------
def test_6_path_too_long(tmp_path):
    with pytest.raises(sm.SurfmodError, match=r"^path: file name of 305 bytes is longer than the limit 255$"):
        sm.export_step(sm.sphere(1.0), "a" * 300 + ".step")
    with pytest.raises(sm.SurfmodError, match=r"^path: file name of 305 bytes"):
        sm.import_step(tmp_path / ("a" * 300 + ".step"))
    with pytest.raises(sm.SurfmodError, match=r"^path: file name of 304 bytes"):
        sm.export_stl(sm.sphere(1.0), "a" * 300 + ".stl")
    with pytest.raises(sm.SurfmodError, match=r"^path: file name .* is too long to write atomically$"):
        sm.export_step(sm.sphere(1.0), tmp_path / ("a" * 240 + ".step"))
    with pytest.raises(sm.SurfmodError, match=r"^path: file path contains a NUL character$"):
        sm.export_step(sm.sphere(1.0), tmp_path / "a\x00.step")


# 7 -------------------------------------------------------------------------------------------
@pytest.mark.parametrize("call, name", [
    (lambda: sm.Arc((0, 0, 0), (0, 0, 1), 2.0, 0, [1, 2]), "end_angle"),
    (lambda: sm.Arc((0, 0, 0), (0, 0, 1), 2.0, np.array([0.0]), 90), "start_angle"),
    (lambda: sm.revolution(LINE, angle=[90, 180]), "angle"),
    (lambda: PLANE.rotated((0, 0, 0), (0, 0, 1), np.zeros(3)), "degrees"),
    (lambda: sm.sweep(sm.Line((-1, 0, 0), (1, 0, 0)), sm.Line((0, 0, 0), (0, 0, 5)), twist=[1, 2]), "twist"),
])
def test_7_an_array_passed_as_an_angle(call, name):
    with pytest.raises(sm.SurfmodError, match=rf"^{name}: expected a single number, got an array of shape"):
        call()


def test_7_a_0d_array_is_an_angle():
    a = sm.Arc((0, 0, 0), (0, 0, 1), 1.0, np.float64(0.0), np.array(90.0))
    np.testing.assert_allclose(a.points(a.domain[1]), [0.0, 1.0, 0.0], atol=1e-15)


# 8 -------------------------------------------------------------------------------------------
COINCIDE = r"^a, b: the surfaces coincide over a region \(within tolerance 1e-06\)"


def test_8_identical_surfaces():
    with pytest.raises(sm.SurfmodError, match=COINCIDE):
        sm.intersect(sm.sphere(1.0), sm.sphere(1.0), 1e-6)


def test_8_overlapping_patches():
    small = sm.plane((0.2, 0.2, 0), (0.5, 0.2, 0), (0.2, 0.5, 0))  # inside PLANE, smaller than a sample cell
    with pytest.raises(sm.SurfmodError, match=COINCIDE):
        sm.intersect(PLANE, small, 1e-6)
    with pytest.raises(sm.SurfmodError, match=COINCIDE):
        sm.intersect(sm.sphere(1.0), sm.sphere(1.0).rotated((0, 0, 0), (0, 0, 1), 30), 1e-6)
    with pytest.raises(sm.SurfmodError, match=r"^a, b: the surfaces coincide over a region"):
        sm.intersect(PLANE, ((0, 0, 0), (0, 0, 1)))


def test_8_touching_is_not_coinciding():
    """A cylinder tangent to a plane along a line, and crossing spheres, still intersect."""
    curves = sm.intersect(sm.sphere(1.0), sm.sphere(1.0, center=(1.0, 0, 0)), 1e-6)
    pts = np.concatenate([c.points for c in curves])
    np.testing.assert_allclose(np.linalg.norm(pts, axis=1), 1.0, atol=1e-9)
    np.testing.assert_allclose(pts[:, 0], 0.5, atol=1e-9)


# 9 -------------------------------------------------------------------------------------------
@pytest.mark.filterwarnings("error")  # a far point must not overflow anywhere on its way (inf, then clipped)
def test_9_far_points():
    e = sm.ellipsoid(1, 2, 3)
    with pytest.raises(sm.SurfmodError, match=r"^points_or_curve: magnitude 1e\+300 exceeds the limit 1e\+70$"):
        sm.project([[0, 0, 1e300]], e)
    pr = sm.project([[0, 0, 1e60]], e)
    np.testing.assert_allclose(pr.point, [[0, 0, 3.0]], atol=1e-9)
    assert pr.distance[0] == pytest.approx(1e60, rel=1e-15)


# 10 ------------------------------------------------------------------------------------------
def test_10_mesh_cap():
    with pytest.raises(sm.SurfmodError, match=r"^max_points: the 10000000 x 5 grid mesh needs about 50,000,000 points, "
                                              r"above the cap 10,000,000; pass max_points= a larger value"):
        sm.mesh(PLANE, 10**7, 5)
    assert len(sm.mesh(PLANE, 3, 3, max_points=9).vertices) == 9
    with pytest.raises(sm.SurfmodError, match=r"^max_points: the 3 x 3 grid mesh needs about 9 points, above the cap 8"):
        sm.mesh(PLANE, 3, 3, max_points=8)


def test_10_evaluation_caps():
    u = np.zeros((3000, 1))
    with pytest.raises(sm.SurfmodError, match=r"^max_points: evaluating \(3000, 4000\) parameters needs about 12,000,000"):
        PLANE.points(u, np.zeros(4000))
    assert PLANE.points(u[:3], np.zeros(4), max_points=12).shape == (3, 4, 3)
    with pytest.raises(sm.SurfmodError, match=r"^max_points: the grid of 4000 x 4000 points"):
        PLANE.grid(np.zeros(4000), np.zeros(4000))


def test_10_project_cap():
    pts = np.zeros((100_001, 3))
    with pytest.raises(sm.SurfmodError, match=r"^max_points: projecting 100,001 points needs about 100,001 points, "
                                              r"above the cap 100,000"):
        sm.project(pts, sm.torus(5, 1))
    pr = sm.project(np.array([[6.0, 0, 0], [0, 0, 5.0]]), sm.torus(5, 1), max_points=2)
    np.testing.assert_allclose(pr.distance, [0.0, np.hypot(5, 5) - 1], atol=1e-12)


def test_10_project_in_blocks_matches_one_block(capsys):
    """Above 10,000 points the work runs block by block (with a progress bar); the
    answer is the same as projecting each point alone."""
    rng = np.random.default_rng(3)
    pts = rng.uniform(-6, 6, (10_050, 3))
    pr = sm.project(pts, sm.torus(5, 1))
    assert "project" in capsys.readouterr().err
    r = np.hypot(np.hypot(pts[:, 0], pts[:, 1]) - 5, pts[:, 2])  # closed form for a torus
    np.testing.assert_allclose(pr.distance, np.abs(r - 1), atol=1e-9)


def test_10_tessellate_cap():
    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4] * 2.0
    net[1:3, 1:3, 2] = [[3, -2], [-1, 4]]
    with pytest.raises(sm.SurfmodError, match=r"max_triangles=250,000"):
        sm.tessellate(sm.BezierSurface(net), 1e-6)


def test_10_intersect_toolpath_femesh_caps():
    import build123d as bd

    with pytest.raises(sm.SurfmodError, match=r"^max_points: tracing with step 1e-09"):
        sm.intersect(sm.sphere(1.0), ((0, 0, 0), (0, 0, 1)), step=1e-9)
    with pytest.raises(sm.SurfmodError, match=r"^max_points: the raster of .* passes"):
        sm.toolpath(PLANE, sm.Tool("ball", 0.5), stepover=1e-4, step=1e-4)
    with pytest.raises(sm.SurfmodError, match=r"^max_elements: a volume mesh with element size 0.001"):
        sm.fe_mesh(bd.Box(1, 1, 1), size=0.001)


# 11 ------------------------------------------------------------------------------------------
def test_11_nan_and_huge_coordinates_are_refused_before_any_use(tmp_path):
    def with_x(value: bytes, name: str) -> Path:
        data = SCREW.read_bytes()
        old = b"#39 = CARTESIAN_POINT('',(-16.45980666667,"
        assert data.count(old) == 1
        out = tmp_path / name
        out.write_bytes(data.replace(old, b"#39 = CARTESIAN_POINT('',(" + value + b","))
        return out

    huge = with_x(b"-1.E20", "screw-huge.step")
    with pytest.raises(sm.DamagedFileError, match=r"^obj: .*screw-huge\.step has coordinates up to 1(\.\d+)?e\+20, beyond"):
        sm.mass_properties(str(huge))
    with pytest.raises(sm.DamagedFileError, match=r"^path: .*screw-huge\.step has coordinates up to 1(\.\d+)?e\+20"):
        sm.import_step(huge)
    assert len(sm.import_step(huge, max_coordinate=1e21).faces()) == 10  # the caller may raise the limit
    with pytest.raises(sm.DamagedFileError, match=r"^path: .*screw-inf\.step has a number that is NaN, infinite "
                                                  r"or beyond 1e\+70 \('1\.E300' at byte \d+\)$"):
        sm.import_step(with_x(b"1.E300", "screw-inf.step"))
    # a control point of inf inside a face: outside the box of edges and bounds, and a
    # later evaluation of its span crashed OCCT (SIGSEGV in the mass integrator)
    data = (CORPUS / "stepcode_HEAD_FRONT.stp").read_bytes()
    old = b"#56=CARTESIAN_POINT('Control Point',(9.84251968504,"
    assert data.count(old) == 1
    # a finite pole inside a face the text scan passes: the box of the geometry holds
    # every pole (1e20 inches: 2.77e21 mm at its corner), so the reader refuses it by that
    pole = tmp_path / "head-huge-pole.stp"
    pole.write_bytes(data.replace(old, b"#56=CARTESIAN_POINT('Control Point',(1.E20,"))
    with pytest.raises(sm.DamagedFileError, match=r"^path: .*head-huge-pole\.stp has coordinates up to 2\.77e\+21, "):
        sm.import_step(pole)
    pole = tmp_path / "head-inf-pole.stp"
    pole.write_bytes(data.replace(old, b"#56=CARTESIAN_POINT('Control Point',(inf,"))
    # OCCT 8.0's reader loops on this pole (over 240 s where the file reads in 3 s): the
    # text is refused before OCCT reads it, the same on every release
    with pytest.raises(sm.DamagedFileError, match=r"^path: .*head-inf-pole\.stp has a number that is NaN, "
                                                  r"infinite or beyond 1e\+70 \('inf' at byte \d+\)$"):
        sm.import_step(pole)
    with pytest.raises(sm.DamagedFileError, match=r"^obj: .*head-inf-pole\.stp has a number that is NaN, infinite"):
        sm.mass_properties(str(pole))


# 12 ------------------------------------------------------------------------------------------
def test_12_wrong_types():
    with pytest.raises(sm.SurfmodError, match=r"^s: expected a surfmod Surface, got str$"):
        sm.mesh("s", 10, 10)
    with pytest.raises(sm.SurfmodError, match=r"^s: expected a surfmod Surface, got Line$"):
        sm.project([0, 0, 0], sm.Line((0, 0, 0), (1, 0, 0)))
    with pytest.raises(sm.SurfmodError, match=r"^mode: expected one of"):
        sm.sweep(sm.Line((-1, 0, 0), (1, 0, 0)), sm.Line((0, 0, 0), (0, 0, 5)), mode=["frenet"])


# 13 ------------------------------------------------------------------------------------------
def test_13_axis_whose_norm_overflows():
    line = sm.Line((1, 0, 0), (1, 0, 4))
    with pytest.raises(sm.SurfmodError, match=r"^axis_direction: magnitude 1e\+300 exceeds the limit 1e\+70$"):
        sm.revolution(sm.Line((0, 0, 0), (0, 0, 4)), (0, 0, 0), (1e300, 1e300, 1e300))
    # a long but representable axis is normalized without overflow
    big = sm.revolution(line, (0, 0, 0), (0, 0, 1e60))
    unit = sm.revolution(line, (0, 0, 0), (0, 0, 1))
    np.testing.assert_array_equal(big.axis_direction, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(big.points(1.0, 2.0), unit.points(1.0, 2.0), rtol=0, atol=1e-15)
    np.testing.assert_allclose(checks.direction((1e70, 1e70, 1e70), "d"), np.full(3, 3**-0.5), rtol=1e-15)


# 4 (non-finite results) ----------------------------------------------------------------------
def test_non_finite_results_raise():
    cusp = sm.BezierCurve([(0, 0, 0), (0, 0, 0), (1, 0, 0)])  # C'(0) = 0: no tangent
    with pytest.raises(sm.SurfmodError, match=r"^t: the tangents at t = 0 are not finite"):
        cusp.tangents([0.5, 0.0])
    np.testing.assert_allclose(cusp.tangents(0.5), [1.0, 0.0, 0.0])

    class Singular(sm.Surface):
        """z = 1 / u: infinite at u = 0."""

        domain = ((0.0, 1.0), (0.0, 1.0))

        def _derivatives(self, u, v, order):
            out = np.zeros((u.size, order + 1, order + 1, 3))
            with np.errstate(divide="ignore"):
                out[:, 0, 0] = np.stack([u, v, 1.0 / u], axis=-1)
            return out

        def geom(self):
            raise NotImplementedError

        def transformed(self, matrix):
            raise NotImplementedError

    with pytest.raises(sm.SurfmodError, match=r"^u, v: the points at \(u, v\) = \(0, 0.5\) are not finite"):
        Singular().points([0.5, 0.0], 0.5)
    with pytest.raises(sm.SurfmodError, match=r"^u, v: the grid at \(u, v\) = \(0, 0.25\) are not finite"):
        Singular().grid([0.5, 0.0], [0.25])


# 14 ------------------------------------------------------------------------------------------
WRITER = textwrap.dedent("""
    import sys, time
    from pathlib import Path
    from surfmod.atomic import atomic_path
    target = Path(sys.argv[1])
    with atomic_path(target) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(b"x" * 5_000_000)
            fh.flush()
            print(tmp.name, flush=True)
            time.sleep(120)       # killed here, mid-write
""")


def _killed_writer(target: Path) -> str:
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(target)], stdout=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)))
    name = proc.stdout.readline().strip()
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    proc.stdout.close()
    return name


def test_14_sigkill_mid_write_leaves_the_target_whole_and_the_litter_is_cleaned(tmp_path):
    target = tmp_path / "part.stl"
    sm.export_stl(sm.sphere(1.0), target, tolerance=0.05)
    before = target.read_bytes()
    name = _killed_writer(target)
    assert name.startswith(".part.stl.surfmod-tmp-") and (tmp_path / name).stat().st_size == 5_000_000
    assert target.read_bytes() == before  # never partial
    # the next write to the same target removes the orphan of the dead writer
    sm.export_stl(sm.sphere(2.0), target, tolerance=0.05)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.stl"]
    assert target.read_bytes() != before


def test_14_a_live_writers_temporary_file_is_left_alone(tmp_path):
    target = tmp_path / "a.step"
    live = tmp_path / f".a.step{atomic.TMP_MARK}{os.getpid()}-00ff"
    other = tmp_path / f".b.step{atomic.TMP_MARK}999999999-00ff"  # another target's litter
    live.write_bytes(b"in progress")
    other.write_bytes(b"not ours to clean")
    sm.export_step(PLANE, target)
    assert live.exists() and other.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, other.name, "a.step"])


def test_14_a_failed_write_removes_its_temporary_file(tmp_path):
    target = tmp_path / "x.txt"
    with pytest.raises(RuntimeError), atomic.atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("writer failed")
    assert list(tmp_path.iterdir()) == []


def test_long_operations_show_progress_on_request(capsys):
    # tessellate, intersect and fe_mesh draw a tqdm bar on stderr with progress=True, and
    # stay silent by default (scripts and CI logs)
    import build123d as bd

    net = np.zeros((4, 4, 3))
    net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    net[1:3, 1:3, 2] = 1.5
    s = sm.BezierSurface(net)
    plane = ((0, 0, 0.5), (0, 0, 1))
    sm.tessellate(s, 0.01)
    sm.intersect(s, plane)
    sm.fe_mesh(bd.Box(2, 2, 2), size=1.0)
    assert capsys.readouterr().err == ""
    sm.tessellate(s, 0.01, progress=True)
    sm.intersect(s, plane, progress=True)
    sm.fe_mesh(bd.Box(2, 2, 2), size=1.0, progress=True)
    err = capsys.readouterr().err
    assert "tessellate" in err and "intersect" in err and "fe_mesh" in err
