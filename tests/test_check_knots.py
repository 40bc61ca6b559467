"""``surfmod check`` at knots where a B-spline is only C1: the second derivatives and the
curvature are two-valued there (each evaluator takes one side), so the check skips them
and says so.  A periodic bicubic with a double knot (multiplicity p - 1), trimmed across
its seam, reported d2_rel 0.73 and curvature_rel 1.45 before: the shifted knot, wrapped
back into the knots' period, lands an ulp to the left while OCCT snaps onto the knot."""

from __future__ import annotations

import math

import numpy as np
import pytest
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.Geom import Geom_BSplineSurface, Geom_RectangularTrimmedSurface
from OCP.gp import gp_Pnt
from surfmod.occ.bindings import TColgp_Array2OfPnt
from surfmod.occ.bindings import TColStd_Array1OfInteger, TColStd_Array1OfReal

import surfmod as sm
from surfmod.cli.check import check_file

KNOTS_U = [0.0, 0.7, 1.3, 2.9, 3.1, 4.4, 2 * math.pi]
MULTS_U = [1, 1, 2, 1, 1, 1, 1]  # 1.3 is a double knot of a cubic: C1 there


def _periodic_c1(mults=MULTS_U, seed=4):
    """A periodic bicubic over the knots ``KNOTS_U`` with multiplicities ``mults`` (random
    radii from ``seed``), clamped in v."""
    rng = np.random.default_rng(seed)
    nu, nv = sum(mults[:-1]), 4
    poles = TColgp_Array2OfPnt(1, nu, 1, nv)
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            r = 2 + 0.3 * rng.uniform(-1, 1)
            poles.SetValue(i + 1, j + 1, gp_Pnt(r * math.cos(a), r * math.sin(a), j + 0.2 * rng.uniform(-1, 1)))
    uk, um = TColStd_Array1OfReal(1, len(KNOTS_U)), TColStd_Array1OfInteger(1, len(KNOTS_U))
    for i, (k, m) in enumerate(zip(KNOTS_U, mults)):
        uk.SetValue(i + 1, k)
        um.SetValue(i + 1, m)
    vk, vm = TColStd_Array1OfReal(1, 2), TColStd_Array1OfInteger(1, 2)
    vk.SetValue(1, 0.0), vk.SetValue(2, 1.0), vm.SetValue(1, 4), vm.SetValue(2, 4)
    return Geom_BSplineSurface(poles, uk, vk, um, vm, 3, 3, True, False)


def _second_derivative_jump(g, u):
    """OCCT's own one-sided second derivatives at ``u``: they differ (the knot is real)."""
    from surfmod.occ.sample import surface_values_d2

    left = surface_values_d2(g, np.array([u - 1e-9]), np.array([0.5]))[0, 2, 0]
    right = surface_values_d2(g, np.array([u + 1e-9]), np.array([0.5]))[0, 2, 0]
    return float(np.linalg.norm(left - right))


@pytest.mark.parametrize("bounds", [(2.0, 2.0 + 2 * math.pi), (-2.5, 1.5), (-5.0, 0.3), (0.0, 2 * math.pi)])
@pytest.mark.parametrize("sampling", ["dense", "sufficient"])
def test_c1_knot_across_the_seam_is_no_false_alarm(bounds, sampling):
    g = _periodic_c1()
    assert _second_derivative_jump(g, 1.3) > 0.1  # a real C1 knot: d2 jumps
    face = sm.from_face(BRepBuilderAPI_MakeFace(g, *bounds, 0.0, 1.0, 1e-7).Face())
    r = sm.crosscheck(face, sampling=sampling)
    assert r.passed, r.details["failed"]
    assert r.details["d2_rel"] < 1e-13 and r.details["curvature_rel"] < 1e-13
    assert r.details["knot_jump_points"] > 0  # and it says where it skipped


def test_c1_knot_of_a_trimmed_bspline_in_a_file(tmp_path):
    rng = np.random.default_rng(3)
    x, y = np.meshgrid(np.linspace(0, 4, 7), np.linspace(0, 3, 6), indexing="ij")
    net = np.stack([x, y, rng.uniform(-1, 1, (7, 6))], -1)
    ku = np.array([0, 0, 0, 0, 0.25, 0.4, 0.4, 1, 1, 1, 1.0])  # 0.4 double: C1
    kv = np.array([0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1.0])
    s = sm.BSplineSurface(net, (3, 3), knots=(ku, kv))
    trimmed = Geom_RectangularTrimmedSurface(s.geom(), 0.13, 0.77, 0.21, 0.83)
    path = tmp_path / "c1.step"
    import build123d as bd

    sm.export_step(bd.Face(BRepBuilderAPI_MakeFace(trimmed, 1e-7).Face()), path)
    [(_, _, kind, dev, ok, note)] = check_file(path, 24)
    assert ok and dev < 1e-12, note
    assert "C1/C0 knot lines" in note


def _periodic_c1_at_the_seam():
    """:func:`_periodic_c1` with its seam knot 0 doubled too: C1 across the seam."""
    return _periodic_c1([2] + MULTS_U[1:-1] + [2], seed=5)


@pytest.mark.parametrize("sampling", ["dense", "sufficient"])
def test_a_c1_seam_knot_at_the_face_edge_is_no_false_alarm(sampling):
    # a face whose trim starts an ulp below the seam (as read from a file: v0 = -4.4e-16 on
    # a PlanetCAD part): surfmod's knot vector of the periodic spline runs on past the
    # seam, so it took the span below while OCCT snaps onto the knot; d2_rel was 0.3 there
    g = _periodic_c1_at_the_seam()
    assert _second_derivative_jump(g, 0.0) > 0.1  # the seam is a real C1 knot
    trimmed = Geom_RectangularTrimmedSurface(g, 0.0, math.pi, 0.0, 1.0)  # as the file has it
    face = sm.from_face(BRepBuilderAPI_MakeFace(trimmed, -4.440892098500626e-16, math.pi, 0.0, 1.0, 1e-7).Face())
    r = sm.crosscheck(face, sampling=sampling)
    assert r.passed, r.details["failed"]
