"""from_face readers for OCCT's analytic surfaces: STEP round trip of build123d and
cadquery primitives, every basis-curve kind of swept surfaces, trimmed and offset surfaces."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from OCP.Geom import Geom_RectangularTrimmedSurface

import surfmod as sm
from surfmod.occ import analytic as occ
from surfmod.occ.geom import bezier_curve, surface_type
from surfmod.occ.sample import surface_d0
from surfmod.occ.topo import face_from_surface, face_surface
from twins.transformed import transformed as occ_transformed

EXPECTED_CLASS = {
    "Geom_Plane": sm.PlaneSurface,
    "Geom_CylindricalSurface": sm.CylindricalSurface,
    "Geom_ConicalSurface": sm.ConicalSurface,
    "Geom_SphericalSurface": sm.SphericalSurface,
    "Geom_ToroidalSurface": sm.ToroidalSurface,
    "Geom_SurfaceOfRevolution": sm.RevolutionSurface,
    "Geom_SurfaceOfLinearExtrusion": sm.TabulatedCylinder,
    "Geom_BSplineSurface": sm.BSplineSurface,
    "Geom_OffsetSurface": sm.OffsetSurface,
}


def _check_face(face):
    """Read a face back; compare with the file's own OCCT surface point for point."""
    surf, bounds, _ = face_surface(face)
    s = sm.from_face(face)
    name = surface_type(surf)
    assert isinstance(s.surface, EXPECTED_CLASS[name]), (name, type(s))
    assert np.ravel(s.domain) == pytest.approx(bounds, abs=1e-12)
    (u0, u1), (v0, v1) = s.domain
    uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(u0, u1, 7), np.linspace(v0, v1, 7)))
    scale = max(1.0, float(np.abs(s.points(uu, vv)).max()))
    dev = float(np.abs(s.points(uu, vv) - surface_d0(surf, uu, vv)).max())
    assert dev <= 1e-13 * scale, (name, dev)
    r = sm.crosscheck(face, samples=10)
    assert r.passed, (name, r.details)
    return name


def _build123d_parts():
    import build123d as bd

    with bd.BuildPart() as rv:
        with bd.BuildSketch(bd.Plane.XZ):
            with bd.BuildLine():
                bd.Spline((2, 0), (3, 1), (2.5, 2), (3, 3))
                bd.Polyline((3, 3), (1.5, 3), (1.5, 0), (2, 0))
            bd.make_face()
        bd.revolve(axis=bd.Axis.Z, revolution_arc=270)
    with bd.BuildPart() as ex:
        with bd.BuildSketch():
            with bd.BuildLine():
                bd.Spline((0, 0), (1, 1), (2, 0.5), (3, 1))
                bd.Polyline((3, 1), (3, -1), (0, -1), (0, 0))
            bd.make_face()
        bd.extrude(amount=2)
    with bd.BuildPart() as el:  # elliptic edges, an ellipse-based extrusion
        with bd.BuildSketch():
            bd.Ellipse(2, 1)
        bd.extrude(amount=1)
    return [
        bd.Box(2, 3, 4),
        bd.Cylinder(1, 3).translate((5, 0, 0)),
        bd.Cone(2, 1, 3).translate((10, 0, 0)),
        bd.Sphere(2).translate((0, 8, 0)),
        bd.Torus(3, 1).translate((0, 16, 0)),
        bd.fillet(bd.Box(4, 4, 4).edges(), 0.5).translate((10, 10, 0)),
        rv.part.translate((20, 0, 0)),
        ex.part.translate((20, 10, 0)),
        el.part.translate((-10, 0, 0)),
    ]


def test_build123d_primitives_step_round_trip(tmp_path):
    import build123d as bd

    path = tmp_path / "primitives.step"
    bd.export_step(bd.Compound(_build123d_parts()), str(path))
    shape = bd.import_step(str(path))
    names = {_check_face(f) for f in shape.faces()}
    assert {
        "Geom_Plane",
        "Geom_CylindricalSurface",
        "Geom_ConicalSurface",
        "Geom_SphericalSurface",
        "Geom_ToroidalSurface",
        "Geom_SurfaceOfRevolution",
        "Geom_SurfaceOfLinearExtrusion",
    } <= names


@pytest.mark.skipif(importlib.util.find_spec("cadquery") is None,
                    reason="cadquery is the 'cadquery' extra (OCCT 7.9); this venv is on the other stack")
def test_cadquery_primitives_step_round_trip(tmp_path):
    import cadquery as cq

    import build123d as bd

    part = (
        cq.Workplane("XY").box(4, 4, 2).faces(">Z").workplane().hole(1.5).edges("|Z").fillet(0.4)
        .union(cq.Workplane("XY").sphere(1.2).translate((0, 0, 2)))
        .union(cq.Workplane("XZ").center(3, 0).circle(0.5).revolve(180, (-3, 0, 0), (-3, 1, 0)).translate((0, 0, 5)))
    )
    path = tmp_path / "cq.step"
    cq.exporters.export(part, str(path))
    shape = bd.import_step(str(path))
    names = {_check_face(f) for f in shape.faces()}
    assert {"Geom_Plane", "Geom_CylindricalSurface", "Geom_SphericalSurface"} <= names


def _basis_curves():
    spline = sm.BSplineCurve([(1, 0, 0), (2, 0, 1), (1.5, 0, 2), (2.5, 0, 3)], 3, weights=[1, 2, 1, 1])
    return {
        "line": (occ.infinite_line((1, 0, -1), (0.3, 0, 1)), (-1.0, 2.0)),
        "circle": (occ.conic("circle", (3, 0, 0), (0, 1, 0), (1, 0, 0), 1.0), (-1.0, 4.0)),
        "ellipse": (occ.conic("ellipse", (3, 0, 0), (0, 1, 0), (0, 0, 1), 1.0, 0.5), (0.5, 6.0)),
        "parabola": (occ.conic("parabola", (3, 0, 0), (0, 1, 0), (0, 0, 1), 0.5), (-1.0, 1.5)),
        "hyperbola": (occ.conic("hyperbola", (1, 0, 0), (0, 1, 0), (1, 0, 0), 1.0, 0.5), (-1.0, 1.2)),
        "bspline": (spline.geom(), (0.2, 0.9)),
        "bezier": (bezier_curve(np.array([(1.0, 0, 0), (2, 0, 1), (1, 0, 3)]), np.array([1.0, 3, 1])), (0.0, 1.0)),
        "trimmed": (occ.trimmed(occ.conic("circle", (3, 0, 0), (0, 1, 0), (1, 0, 0), 1.0), -1.0, 2.0), (-1.0, 2.0)),
    }


@pytest.mark.parametrize("kind", sorted(_basis_curves()))
def test_revolution_and_extrusion_keep_occt_parametrization_of_every_basis_curve(kind):
    curve, (t0, t1) = _basis_curves()[kind]
    rev = occ.revolution(curve, (0, 0, 0), (0, 0, 1))
    assert _check_face(face_from_surface(rev, 0.3, 5.0, t0, t1)) == "Geom_SurfaceOfRevolution"
    ext = occ.extrusion(curve, (0.2, 1.0, 0.1))
    assert _check_face(face_from_surface(ext, t0, t1, -1.0, 2.0)) == "Geom_SurfaceOfLinearExtrusion"


def test_rectangular_trimmed_surface_is_unwrapped():
    cyl = occ.elementary("cylinder", (np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0])), 2.0)
    trimmed = Geom_RectangularTrimmedSurface(cyl, 0.5, 2.5, -1.0, 3.0)
    face = face_from_surface(trimmed, 0.7, 2.0, 0.0, 2.0)
    s = sm.from_face(face)
    assert isinstance(s.surface, sm.CylindricalSurface)
    assert s.domain == ((0.7, 2.0), (0.0, 2.0))
    assert sm.crosscheck(face).passed


@pytest.mark.parametrize(
    "base",
    [
        sm.BSplineSurface(
            np.stack([*np.meshgrid(np.arange(4.0), np.arange(5.0), indexing="ij"), np.sin(np.add.outer(np.arange(4.0), 0.5 * np.arange(5.0)))], -1),
            (3, 2),
        ),
        sm.sphere(2.0),
        sm.torus(3.0, 1.0),
        sm.CylindricalSurface(1.0, v_range=(0, 2)),
        sm.PlaneSurface((0, 0, 1), (0, 1, 1), u_range=(0, 2), v_range=(0, 1)),
        sm.ConicalSurface(0.4, 1.0, v_range=(0.0, 2.0)),
    ],
    ids=["bspline", "sphere", "torus", "cylinder", "plane", "cone"],
)
@pytest.mark.parametrize("distance", [0.3, -0.4])
def test_offset_surface(base, distance):
    face = face_from_surface(occ.offset_surface(base.geom(), distance), *np.ravel(base.domain))
    s = sm.from_face(face)
    assert isinstance(s.surface, sm.OffsetSurface)
    (u0, u1), (v0, v1) = s.domain
    uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(u0, u1, 7), np.linspace(v0 + 0.05, v1 - 0.05, 7)))
    np.testing.assert_allclose(s.points(uu, vv), base.points(uu, vv) + distance * base.normals(uu, vv), atol=1e-13)
    np.testing.assert_allclose(s.normals(uu, vv), base.normals(uu, vv), atol=1e-12)
    r = sm.crosscheck(face, samples=10)
    assert r.passed, r.details


def test_offset_jets_match_occt_on_a_bspline_to_second_order():
    rng = np.random.default_rng(7)
    net = np.stack([*np.meshgrid(np.arange(5.0), np.arange(5.0), indexing="ij"), rng.uniform(-0.5, 0.5, (5, 5))], -1)
    base = sm.BSplineSurface(net, (3, 3), weights=rng.uniform(0.5, 2.0, (5, 5)))
    s = sm.OffsetSurface(base, 0.7)
    from surfmod.occ.sample import surface_d2

    uu, vv = rng.uniform(0, 1, 40), rng.uniform(0, 1, 40)
    mine = s.derivatives(uu, vv, 2)
    ref = surface_d2(s.geom(), uu, vv)
    idx = ([0, 1, 0, 2, 1, 0], [0, 0, 1, 0, 1, 2])
    scale = np.abs(ref[:, idx[0], idx[1]]).max()
    np.testing.assert_allclose(mine[:, idx[0], idx[1]], ref[:, idx[0], idx[1]], atol=1e-11 * scale)


def test_offset_similarity_transform_matches_gp_trsf():
    from surfmod.transforms import mirror_matrix

    base = sm.torus(3.0, 1.0)
    s = sm.OffsetSurface(base, 0.25)
    m = mirror_matrix((1, 0, 0), (1, 2, 3))
    t = s.transformed(m)
    uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(0, 6, 5), np.linspace(0, 6, 5)))
    np.testing.assert_allclose(t.points(uu, vv), surface_d0(occ_transformed(s.geom(), m), uu, vv), atol=1e-13)


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: sm.OffsetSurface("sphere", 1.0), "base"),
        (lambda: sm.OffsetSurface(sm.sphere(1.0), float("nan")), "distance"),
        (lambda: sm.OffsetSurface(sm.sphere(1.0), 0.1).scaled((1, 2, 1)), "matrix"),
    ],
)
def test_bad_input(call, name):
    with pytest.raises(sm.SurfmodError, match=name):
        call()


def test_closed_nurbs_come_back_periodic_from_step_and_still_read(tmp_path):
    """OCCT re-reads closed rational B-splines (ellipsoid, revolved NURBS) as periodic."""
    import build123d as bd

    faces = [sm.ellipsoid(3.0, 2.0, 1.0).face(), sm.revolution(sm.Circle((3, 0, 0), (0, 1, 0), 1.0)).to_nurbs().face()]
    path = tmp_path / "closed.step"
    sm.export_step(faces, path)
    shape = bd.import_step(str(path))
    assert len(shape.faces()) == 2
    for face in shape.faces():
        s = sm.from_face(face)
        assert isinstance(s.surface, sm.BSplineSurface) and s.rational
        assert sm.crosscheck(face, samples=10).passed


def test_offset_grid_fast_path_equals_scattered_evaluation():
    rng = np.random.default_rng(3)
    s = sm.OffsetSurface(sm.BSplineSurface(rng.uniform(0, 1, (5, 4, 3)), (3, 2)), 0.2)
    us, vs = np.linspace(0, 1, 7), np.linspace(0, 1, 5)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    for order in (0, 2):
        np.testing.assert_allclose(s.grid_derivatives(us, vs, order), s.derivatives(uu, vv, order), atol=1e-12)
