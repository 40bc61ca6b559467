"""FaceSurface, the evaluator mesh measurement uses on a face's surface, equals OCCT's
own evaluation where the face lives: an extrusion of a spline curve given its UV box is
evaluated as an exact B-spline net (positions and partials to order 2 equal OCCT's D2,
its compiled projection finds the distance along the normal), swept surfaces are the
surfmod surfaces readback reads and wrap periodic parameters as OCCT does, and a type
the reader does not know is evaluated by OCCT per point."""

from __future__ import annotations

import numpy as np
import pytest
from OCP.Geom import Geom_OffsetCurve, Geom_SurfaceOfLinearExtrusion, Geom_SurfaceOfRevolution
from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Vec

import surfmod as sm
from surfmod.meshing.facesurface import FaceSurface


def _curve(kind: str):
    pts = np.array([[0, 0, 0], [1, 2, 0.5], [2.5, 1.5, -0.3], [3, -0.5, 0.2], [4.2, 0.4, 1.0], [5, 1, 0]], float)
    if kind == "bezier":
        return sm.BezierCurve(pts, weights=[1.0, 0.8, 1.5, 1.1, 0.9, 1.0]).geom()
    knots = [0, 0, 0, 0, 0.3, 0.7, 1, 1, 1, 1]
    weights = None if kind == "plain" else np.array([1.0, 1.7, 0.6, 1.2, 2.0, 1.0])
    geom = sm.BSplineCurve(pts, 3, knots, weights).geom()
    if kind == "periodic":
        geom.SetPeriodic()
    return geom


def _occt_d2(surf, u, v) -> np.ndarray:
    out = np.zeros((len(u), 3, 3, 3))
    p, du, dv, duu, dvv, duv = gp_Pnt(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec(), gp_Vec()
    for a, (uu, vv) in enumerate(zip(u, v)):
        surf.D2(float(uu), float(vv), p, du, dv, duu, dvv, duv)
        out[a, 0, 0], out[a, 1, 0], out[a, 0, 1] = p.Coord(), du.Coord(), dv.Coord()
        out[a, 2, 0], out[a, 0, 2], out[a, 1, 1] = duu.Coord(), dvv.Coord(), duv.Coord()
    return out


@pytest.mark.parametrize("kind", ["plain", "rational", "periodic", "bezier"])
def test_extrusion_of_a_spline_is_an_exact_net(kind):
    surf = Geom_SurfaceOfLinearExtrusion(_curve(kind), gp_Dir(0.3, -0.2, 0.9))
    bounds = (0.1, 0.8, -1.5, 2.0)
    ev = FaceSurface(surf, bounds)
    assert ev.spline and ev.projector is not None
    rng = np.random.default_rng(3)
    u = rng.uniform(0.0, 1.0, 300)
    v = rng.uniform(-5.0, 5.5, 300)  # the box widened by its size on each side
    ref = _occt_d2(surf, u, v)
    ours = ev.d2(u, v)
    scale = np.abs(ref).max(axis=(0, 3), keepdims=True)[0]  # per partial
    assert np.abs(ours - ref).max(axis=(0, 3)).max() <= 1e-12 * scale.max()
    np.testing.assert_allclose(ev.d0(u, v), ref[:, 0, 0], rtol=0, atol=1e-12 * np.abs(ref[:, 0, 0]).max())
    if kind == "periodic":  # past the seam: the period wraps, as OCCT evaluates it
        np.testing.assert_allclose(ev.d0(u + 1.0, v), ref[:, 0, 0], rtol=0, atol=1e-12 * np.abs(ref).max())
    # points moved off along the normal project back to that distance (away from the
    # box's sides, where the nearest point may lie outside the box)
    inner = (u > 0.1) & (u < 0.9) & (v > -4.5) & (v < 5.0)
    n = np.cross(ref[inner, 1, 0], ref[inner, 0, 1])
    n /= np.linalg.norm(n, axis=1)[:, None]
    pts = ref[inner, 0, 0] + 0.01 * n
    guess = np.column_stack([u, v])[inner] + rng.normal(0, 0.02, (inner.sum(), 2))
    d = ev.projector(pts, guess, (0.0, 1.0, -5.0, 5.5))
    np.testing.assert_allclose(d, 0.01, rtol=1e-6)


def test_extrusion_without_a_box_keeps_the_closed_form():
    surf = Geom_SurfaceOfLinearExtrusion(_curve("rational"), gp_Dir(0, 0, 1))
    ev = FaceSurface(surf)
    assert not ev.spline and ev.numpy
    u, v = np.array([0.2, 0.9]), np.array([-30.0, 40.0])  # no clamp in v: OCCT's C(u) + v D
    np.testing.assert_allclose(ev.d0(u, v), _occt_d2(surf, u, v)[:, 0, 0], rtol=0, atol=1e-12 * 40)


def test_revolution_of_a_periodic_curve_wraps_its_parameter():
    surf = Geom_SurfaceOfRevolution(_curve("periodic"), gp_Ax1(gp_Pnt(0, -3, 0), gp_Dir(1, 0, 0)))
    ev = FaceSurface(surf)
    assert ev.periodic == (True, True)
    u, v = np.array([0.3, 2.0, 5.9]), np.array([0.25, 0.6, 0.95])
    ref = _occt_d2(surf, u, v)[:, :2, :2]
    for shift in (0.0, 1.0, -2.0):  # whole periods of the basis curve
        got = ev.d1(u + 2 * np.pi, v + shift)
        for k, l in ((0, 0), (1, 0), (0, 1)):
            np.testing.assert_allclose(got[:, k, l], ref[:, k, l], rtol=0, atol=1e-12 * np.abs(ref).max())


def test_revolution_of_a_curve_the_reader_does_not_know_is_evaluated_by_occt():
    offset = Geom_OffsetCurve(_curve("plain"), 0.25, gp_Dir(0, 0, 1))  # no surfmod reader
    surf = Geom_SurfaceOfRevolution(offset, gp_Ax1(gp_Pnt(0, -3, 0), gp_Dir(1, 0, 0)))
    ev = FaceSurface(surf, (0.0, 1.0, 0.2, 0.8))
    assert not ev.numpy and not ev.spline
    u, v = np.array([0.3, 2.0, 5.9]), np.array([0.25, 0.6, 0.75])
    ref = _occt_d2(surf, u, v)
    got = ev.d1(u, v)
    for k, l in ((0, 0), (1, 0), (0, 1)):
        np.testing.assert_array_equal(got[:, k, l], ref[:, k, l])
    np.testing.assert_array_equal(ev.d0(u, v), ref[:, 0, 0])
