"""B-spline curves and B-spline / Bézier surfaces read through OCCT's binary writer equal
the same geometry read pole by pole through OCP, bit for bit: polynomial, rational,
periodic (unwrapped), 3-D curves and 2-D p-curves, repeated handles, Bézier surfaces, and
every B-spline p-curve and spline surface of the corpus."""

from __future__ import annotations

import build123d as bd
import numpy as np
import pytest
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve2d
from OCP.Geom import Geom_BSplineSurface
from OCP.GeomAbs import GeomAbs_BSplineCurve
from OCP.TopAbs import TopAbs_EDGE
from OCP.TopoDS import TopoDS

import surfmod as sm
from surfmod.occ import arrays
from surfmod.occ.geom import bspline_curves
from surfmod.occ.geom import (_padded, downcast_surface, read_bezier_surface, read_bspline_curve,
                               read_bspline_surface)
from surfmod.occ.topo import explore, faces_of


def _pole_by_pole(curve) -> dict:
    if curve.IsPeriodic():
        curve = curve.Copy()
        curve.SetNotPeriodic()
    n = curve.NbPoles()
    pts = np.array([curve.Pole(i).Coord() for i in range(1, n + 1)])
    if pts.shape[1] == 2:
        pts = np.column_stack([pts, np.zeros(n)])
    w = np.array([curve.Weight(i) for i in range(1, n + 1)]) if curve.IsRational() else None
    k = curve.NbKnots()
    knots = np.repeat([curve.Knot(i) for i in range(1, k + 1)], [curve.Multiplicity(i) for i in range(1, k + 1)])
    return {"points": pts, "weights": w, "knots": knots, "degree": curve.Degree()}


def read_bspline_curves_2d(curves: list) -> list[dict]:
    """The B-spline p-curves of many faces through one binary table, as read_bspline_curve reads one."""
    return [_padded(d) for d in bspline_curves(curves, 2)]


def _same(a: dict, b: dict) -> bool:
    return (a["degree"] == b["degree"] and np.array_equal(a["points"], b["points"])
            and np.array_equal(a["knots"], b["knots"])
            and ((a["weights"] is None and b["weights"] is None) or np.array_equal(a["weights"], b["weights"])))


def _pcurves(shape):
    out = []
    for face in faces_of(shape):
        for e in explore(face, TopAbs_EDGE):
            pc = BRepAdaptor_Curve2d(TopoDS.Edge(e), face)
            if pc.GetType() == GeomAbs_BSplineCurve:
                out.append(pc.BSpline())
    return out


PTS = [(0, 0, 0), (3, -1, 0.5), (5, 1, 1), (4, 4, 0), (1, 3, -1)]


@pytest.mark.parametrize("kind", ["polynomial", "rational", "periodic"])
def test_3d_curves_equal_pole_by_pole(kind):
    if kind == "periodic":
        geom = BRep_Tool.Curve_s(bd.Spline(*PTS, periodic=True).wrapped, 0.0, 0.0)
        assert geom.IsPeriodic()
    else:
        w = [1.0, 0.7, 1.3, 0.9, 1.1] if kind == "rational" else None
        geom = sm.BSplineCurve(PTS, 3, [0, 0, 0, 0, 0.4, 1, 1, 1, 1], w).geom()
    assert _same(read_bspline_curve(geom), _pole_by_pole(geom))


def test_pcurves_rational_and_periodic_and_repeated_equal_pole_by_pole():
    knots = [0, 0, 0, 1 / 3, 2 / 3, 1, 1, 1]
    rational = sm.BSplineCurve([p[:2] + (0,) for p in PTS], 2, knots, [1.0, 0.7, 1.3, 0.9, 1.1])
    faces = [bd.Face(bd.Wire([rational.edge(), bd.Edge.make_line(PTS[-1][:2] + (0,), (0, 0, 0))])),
             bd.Face(bd.Wire([bd.Spline(*[p[:2] + (0,) for p in PTS], periodic=True)]))]
    curves = [c for f in faces for c in _pcurves(f.wrapped)]
    assert any(c.IsRational() for c in curves) and any(c.IsPeriodic() for c in curves)
    for c in curves:
        assert _same(read_bspline_curve(c), _pole_by_pole(c))
    plain = [c for c in curves if not c.IsPeriodic()]
    # one table for many curves, one of them twice: every entry in the caller's order
    for got, c in zip(read_bspline_curves_2d(plain + plain[:1]), plain + plain[:1]):
        assert _same(got, _pole_by_pole(c))
    raw = bspline_curves([c for c in curves if c.IsPeriodic()], 2)[0]
    assert raw["periodic"]  # stored as is; read_bspline_curve unwraps


@pytest.mark.corpus
def test_every_corpus_pcurve_equals_pole_by_pole(corpus_file):
    curves = _pcurves(sm.import_step(corpus_file).wrapped)
    plain = [c for c in curves if not c.IsPeriodic()]
    for got, c in zip(read_bspline_curves_2d(plain), plain):
        assert _same(got, _pole_by_pole(c))
    for c in curves:
        if c.IsPeriodic():
            assert _same(read_bspline_curve(c), _pole_by_pole(c))


# -- surfaces ------------------------------------------------------------------------------------
def _surface_pole_by_pole(surf) -> dict:
    if surf.IsUPeriodic() or surf.IsVPeriodic():
        surf = surf.Copy()
        if surf.IsUPeriodic():
            surf.SetUNotPeriodic()
        if surf.IsVPeriodic():
            surf.SetVNotPeriodic()
    n, m = surf.NbUPoles(), surf.NbVPoles()
    pts = np.array([[surf.Pole(i, j).Coord() for j in range(1, m + 1)] for i in range(1, n + 1)])
    rational = surf.IsURational() or surf.IsVRational()
    w = np.array([[surf.Weight(i, j) for j in range(1, m + 1)] for i in range(1, n + 1)]) if rational else None
    out = {"control_points": pts, "weights": w}
    if hasattr(surf, "NbUKnots"):
        def flat(knot, mult, count):
            return np.repeat([knot(i) for i in range(1, count + 1)], [mult(i) for i in range(1, count + 1)])

        out["knots"] = (flat(surf.UKnot, surf.UMultiplicity, surf.NbUKnots()),
                        flat(surf.VKnot, surf.VMultiplicity, surf.NbVKnots()))
        out["degree"] = (surf.UDegree(), surf.VDegree())
    return out


def _same_surface(a: dict, b: dict) -> bool:
    same = np.array_equal(a["control_points"], b["control_points"]) and (
        (a["weights"] is None and b["weights"] is None) or np.array_equal(a["weights"], b["weights"]))
    if "knots" in b:
        same = same and a["degree"] == b["degree"] and all(np.array_equal(x, y) for x, y in zip(a["knots"], b["knots"]))
    return same


NET = np.zeros((4, 5, 3))
NET[..., 0], NET[..., 1] = np.mgrid[0:4, 0:5]
NET[..., 2] = np.sin(NET[..., 0]) * np.cos(NET[..., 1])
WEIGHTS = 1.0 + 0.1 * np.arange(20.0).reshape(4, 5) % 3


@pytest.mark.parametrize("kind", ["polynomial", "rational", "periodic", "bezier", "rational bezier"])
def test_surfaces_equal_pole_by_pole(kind):
    if kind in ("bezier", "rational bezier"):
        geom = sm.BezierSurface(NET, WEIGHTS if kind == "rational bezier" else None).geom()
        assert _same_surface(read_bezier_surface(geom), _surface_pole_by_pole(geom))
        return
    if kind == "periodic":  # periodic in u (4 poles, 5 simple knots), rational
        uk, um = arrays.reals_1d([0, 1, 2, 3, 4]), arrays.ints_1d([1] * 5)
        vk, vm = arrays.knots_and_mults([0, 0, 0, 0, 0.3, 1, 1, 1, 1])
        geom = Geom_BSplineSurface(arrays.points_2d(NET), arrays.reals_2d(WEIGHTS), uk, vk, um, vm, 2, 3, True, False)
        assert geom.IsUPeriodic()
    else:
        w = WEIGHTS if kind == "rational" else None
        geom = sm.BSplineSurface(NET, (2, 3), ([0, 0, 0, 0.5, 1, 1, 1], [0, 0, 0, 0, 0.3, 1, 1, 1, 1]), w).geom()
    assert _same_surface(read_bspline_surface(geom), _surface_pole_by_pole(geom))


@pytest.mark.corpus
def test_every_corpus_spline_surface_equals_pole_by_pole(corpus_file):
    for face in faces_of(sm.import_step(corpus_file).wrapped):
        geom = downcast_surface(BRep_Tool.Surface_s(face))
        name = type(geom).__name__
        if name == "Geom_BSplineSurface":
            assert _same_surface(read_bspline_surface(geom), _surface_pole_by_pole(geom))
        elif name == "Geom_BezierSurface":
            assert _same_surface(read_bezier_surface(geom), _surface_pole_by_pole(geom))
