"""Mass properties by Gauss quadrature on the NumPy evaluator vs closed forms and BRepGProp."""

from __future__ import annotations

import math

import numpy as np
import pytest

import surfmod as sm

import build123d as bd


def spline_block(seed=1, n=6, p=3):
    """A block 2 x 3 with a random bicubic B-spline top; its volume has a closed form:
    x, y are linear in (u, v) (Greville control abscissae), so V = 6 Σ z_ij ∫N_i ∫N_j."""
    k = np.concatenate([[0] * p, np.linspace(0, 1, n - p + 1), [1] * p])
    g = np.array([k[i + 1:i + p + 1].mean() for i in range(n)])
    z = 1 + 0.3 * np.random.default_rng(seed).random((n, n))
    net = np.stack(np.broadcast_arrays(2 * g[:, None], 3 * g[None, :], z), -1)
    top = sm.BSplineSurface(net, (p, p), (k, k))
    bot = net.copy()
    bot[..., 2] = 0
    sides = [sm.BSplineSurface(np.stack([a, b]), (1, p), ([0, 0, 1, 1], k))
             for a, b in [(net[0], bot[0]), (net[-1], bot[-1]), (net[:, 0], bot[:, 0]), (net[:, -1], bot[:, -1])]]
    w = (k[p + 1:] - k[:-p - 1]) / (p + 1)
    return [top, sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0)), *sides], 6 * np.einsum("i,j,ij", w, w, z)


def rel(a, b):
    return abs(a - b) / abs(b)


def test_sphere_closed_form():
    r = sm.mass_properties(bd.Sphere(2).translate((1, -2, 3)), density=2.5)
    v = 4 / 3 * math.pi * 8
    assert rel(r.volume, v) < 1e-14 and rel(r.area, 16 * math.pi) < 1e-14
    assert np.allclose(r.centroid, (1, -2, 3), rtol=0, atol=1e-14)
    assert np.allclose(r.inertia, np.eye(3) * 0.4 * 2.5 * v * 4, rtol=1e-14, atol=1e-12)
    assert r.mass == pytest.approx(2.5 * v, rel=1e-14)


def test_torus_closed_form():
    R, a = 3.0, 1.0
    r = sm.mass_properties(bd.Torus(R, a))
    v = 2 * math.pi**2 * R * a * a
    assert rel(r.volume, v) < 1e-14 and rel(r.area, 4 * math.pi**2 * R * a) < 1e-14
    expect = np.diag([v * (R * R / 2 + 5 / 8 * a * a)] * 2 + [v * (R * R + 3 / 4 * a * a)])
    assert np.abs(r.inertia - expect).max() / expect.max() < 1e-14


def test_box_and_cylinder_closed_forms():
    r = sm.mass_properties(bd.Box(2, 3, 4).rotate(bd.Axis.Z, 0))
    assert (r.volume, r.area) == pytest.approx((24.0, 52.0), rel=1e-15)
    assert np.allclose(r.inertia, np.diag([2 * (9 + 16), 2 * (4 + 16), 2 * (4 + 9)]), rtol=1e-14, atol=1e-13)
    c = sm.mass_properties(bd.Cylinder(1.5, 4))
    v = math.pi * 1.5**2 * 4
    assert rel(c.volume, v) < 1e-14
    expect = np.diag([v * (3 * 1.5**2 + 16) / 12] * 2 + [v * 1.5**2 / 2])
    assert np.abs(c.inertia - expect).max() / expect.max() < 1e-14
    assert c.faces == {"natural": 1, "trimmed": 2}  # the discs are trimmed planes


def test_rotated_box_inertia_is_rotated():
    rot = bd.Box(2, 3, 4).rotate(bd.Axis((0, 0, 0), (1, 1, 0)), 30)
    r = sm.mass_properties(rot)
    assert np.allclose(np.sort(r.principal_moments), [26.0, 40.0, 50.0], rtol=1e-13)
    assert abs(r.inertia[0, 1]) > 1  # products of inertia appear, sign convention -∫xy


def test_spline_solid_vs_closed_form_and_brepgprop():
    faces, exact = spline_block()
    r = sm.mass_properties(faces)
    assert r.evaluators == {"numpy": 6, "occt": 0}
    assert rel(r.volume, exact) < 1e-13
    tight = sm.mass_properties(faces, method="occt", eps=1e-9)
    assert rel(tight.volume, exact) < 1e-9
    assert rel(r.area, tight.area) < 1e-9
    assert np.abs(r.centroid - tight.centroid).max() < 1e-9
    assert np.abs(r.inertia - tight.inertia).max() / np.abs(r.inertia).max() < 1e-8


def test_trimmed_faces_green_theorem():
    part = bd.Box(2, 2, 2) - bd.Cylinder(0.5, 3)
    r = sm.mass_properties(part)
    assert r.faces["trimmed"] == 2
    assert rel(r.volume, 8 - math.pi * 0.25 * 2) < 1e-14
    assert rel(r.area, 24 - 2 * math.pi * 0.25 + 2 * math.pi * 0.5 * 2) < 1e-14
    cut = bd.Box(2, 2, 2) - bd.Sphere(1.3)  # spherical faces trimmed by approximated p-curves
    r = sm.mass_properties(cut)
    o = sm.mass_properties(cut, method="occt", eps=1e-9)
    assert r.faces == {"natural": 0, "trimmed": 7}
    assert rel(r.volume, o.volume) < 1e-9 and rel(r.area, o.area) < 1e-12


def test_step_file(tmp_path):
    path = tmp_path / "t.step"
    sm.export_step(bd.Torus(3, 1).translate((0, 0, 2)), path)
    r = sm.mass_properties(str(path))
    assert rel(r.volume, 2 * math.pi**2 * 3) < 1e-11  # STEP text keeps ~15 digits
    assert np.allclose(r.centroid, (0, 0, 2), atol=1e-11)
    assert "volume" in str(r) and "Ixy = -∫xy" in str(r)


def test_open_shell_is_refused():
    with pytest.raises(sm.SurfmodError, match="obj: .*closed"):
        sm.mass_properties(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)))
    faces, _ = spline_block()
    with pytest.raises(sm.SurfmodError, match="obj: .*closed"):
        sm.mass_properties(faces[:-1])


@pytest.mark.parametrize("kw, arg", [({"density": 0}, "density"), ({"density": -1}, "density"),
                                     ({"method": "magic"}, "method"), ({"order": 1}, "order")])
def test_bad_arguments(kw, arg):
    with pytest.raises(sm.SurfmodError, match=arg):
        sm.mass_properties(bd.Box(1, 1, 1), **kw)


def test_unreadable_files(tmp_path):
    with pytest.raises(sm.SurfmodError, match="obj: no such file"):
        sm.mass_properties(tmp_path / "missing.step")
    bad = tmp_path / "bad.step"
    bad.write_text("hello")
    with pytest.raises(sm.SurfmodError, match="obj: .*STEP"):
        sm.mass_properties(bad)
    with pytest.raises(sm.SurfmodError, match="obj: expected"):
        sm.mass_properties(42)


def test_closed_surfmod_surfaces_use_their_own_evaluator():
    r = sm.mass_properties(sm.sphere(2))
    assert r.evaluators == {"numpy": 1, "occt": 0}
    assert rel(r.volume, 4 / 3 * math.pi * 8) < 1e-14 and rel(r.area, 16 * math.pi) < 1e-14
    t = sm.mass_properties(sm.torus(3, 1))
    v = 2 * math.pi**2 * 3
    assert rel(t.volume, v) < 1e-14
    assert rel(t.inertia[2, 2], v * (9 + 0.75)) < 1e-14


def _rational_semicircle():
    """The upper half of the unit circle as one rational cubic span (weights 1, 1/3, 1/3, 1)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.Geom import Geom_BSplineCurve
    from surfmod.occ.bindings import TColgp_Array1OfPnt
    from surfmod.occ.bindings import TColStd_Array1OfInteger, TColStd_Array1OfReal
    from OCP.gp import gp_Pnt

    poles, weights = TColgp_Array1OfPnt(1, 4), TColStd_Array1OfReal(1, 4)
    for i, ((x, y), w) in enumerate(zip([(1, 0), (1, 2), (-1, 2), (-1, 0)], [1, 1 / 3, 1 / 3, 1]), start=1):
        poles.SetValue(i, gp_Pnt(x, y, 0))
        weights.SetValue(i, w)
    knots, mults = TColStd_Array1OfReal(1, 2), TColStd_Array1OfInteger(1, 2)
    for i, k in enumerate([0.0, 1.0], start=1):
        knots.SetValue(i, k)
        mults.SetValue(i, 4)
    return bd.Edge(BRepBuilderAPI_MakeEdge(Geom_BSplineCurve(poles, weights, knots, mults, 3)).Edge())


def test_a_rational_semicircle_integrates_to_round_off():
    # one cubic span whose weights part by 3: at 12 Gauss nodes the volume was 7e-10 and
    # the centroid 9e-9 off; its span is split in two by its weights (mass.breaks)
    arc = _rational_semicircle()
    assert abs(arc.position_at(0.5).Y - 1) < 1e-4  # on the unit circle
    solid = bd.extrude(bd.Face(bd.Wire([arc, bd.Edge.make_line((-1, 0, 0), (1, 0, 0))])), 2.0)
    r = sm.mass_properties(solid)
    assert rel(r.volume, math.pi) < 1e-14
    assert np.allclose(r.centroid, (0, 4 / (3 * math.pi), 1), rtol=0, atol=1e-14)
    # Izz about the centroid: the half disc's polar moment π/4 less Steiner's term, times h = 2
    izz = 2 * (math.pi / 4 - math.pi / 2 * (4 / (3 * math.pi)) ** 2)
    assert rel(r.inertia[2, 2], izz) < 1e-13


def test_moments_of_an_open_boundary_turn_with_the_part():
    """On a boundary that does not close (a p-curve moved 0.05 across its face) the
    integrals depend on the fields: the radial ones (BRepGProp's) give the same tensor,
    turned, when the part turns, and agree with BRepGProp's about the same point.  Per-axis
    fields (``x_i² n_i``) moved by 3e-3 under a rotation on a real file."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Copy, BRepBuilderAPI_Transform
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec2d

    from surfmod.occ.properties import gprops
    from surfmod.occ.topo import faces_of

    solid = BRepBuilderAPI_Copy(bd.Box(10, 20, 30).wrapped).Shape()
    face = faces_of(solid)[0]
    edge = TopoDS.Edge(TopExp_Explorer(face, TopAbs_EDGE).Current())
    moved = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 1.0).Translated(gp_Vec2d(0.05, 0.05))
    BRep_Builder().UpdateEdge(edge, moved, face, BRep_Tool.Tolerance_s(edge))
    axis, angle = np.array([1.0, 2.0, 3.0]) / math.sqrt(14), 0.7
    turn = gp_Trsf()
    turn.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(*axis)), angle)
    turned = BRepBuilderAPI_Transform(solid, turn, True).Shape()
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    q = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
    a, b = sm.mass_properties(solid), sm.mass_properties(turned)
    big = np.abs(a.inertia).max()
    assert np.abs(q @ a.centroid - b.centroid).max() < 1e-13 * 30
    assert np.abs(q @ a.inertia @ q.T - b.inertia).max() < 1e-13 * big
    occ = gprops(solid, 1e-13)
    assert rel(a.volume, occ["volume"]) < 1e-13 and np.abs(a.centroid - occ["centroid"]).max() < 1e-12 * 30
    assert np.abs(a.inertia - occ["inertia"]).max() < 1e-12 * big
    # and the boundary is open: about another point the volume is another
    assert abs(sm.boundary_ambiguity(solid)) > 1e-5


def test_a_closed_surface_of_a_rational_profile_splits_its_spans_too():
    # the unit sphere as the revolution of that semicircle (a closed surfmod surface goes
    # through its own breaks, not a face's): its volume was 3e-8 off at 12 nodes
    profile = sm.BSplineCurve(np.array([[0, 0, -1], [2, 0, -1], [2, 0, 1], [0, 0, 1.0]]), 3,
                              [0, 0, 0, 0, 1, 1, 1, 1], weights=[1, 1 / 3, 1 / 3, 1])
    r = sm.mass_properties(sm.revolution(profile))
    v = 4 / 3 * math.pi
    assert rel(r.volume, v) < 1e-14
    assert np.allclose(r.inertia, 0.4 * v * np.eye(3), rtol=0, atol=1e-11)
