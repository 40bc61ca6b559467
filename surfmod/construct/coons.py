"""Coons patches (:func:`coons`): the surface spanned by four boundary curves, as an exact
B-spline, bilinearly blended or with OCCT's Hermite blend (``GeomFill_Coons``), equal to
OCCT's net pole for pole for polynomial curves.
See :doc:`/guide/surfaces` (section "Coons, ruled and lofted surfaces").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..nets.bspline import BSplineSurface, cartesian, homogeneous
from ..nets.elevate import elevate_degree, elevated, make_compatible
from ..nets.knots import greville
from .from_edge import as_curve

BLENDS = ("linear", "hermite")
NAMES = ("c0", "c1", "d0", "d1")


class CoonsSurface(BSplineSurface):
    """A Coons patch (:doc:`/guide/surfaces` (section "Coons, ruled and lofted surfaces"));
    a B-spline surface that *is* its OCCT twin.  Attributes: ``boundaries`` (``c0, c1, d0,
    d1`` as given), ``blend``.

    :meth:`occt_fill` builds OCCT's ``GeomFill_BSplineCurves`` Coons-style surface on
    the same curves (equal to this one for ``blend="hermite"`` and for translational
    networks).

    >>> import surfmod as sm
    >>> c0 = sm.Line((0, 0, 0), (2, 0, 0)); c1 = sm.Line((0, 2, 1), (2, 2, 1))
    >>> d0 = sm.Line((0, 0, 0), (0, 2, 1)); d1 = sm.Line((2, 0, 0), (2, 2, 1))
    >>> s = sm.coons(c0, c1, d0, d1)
    >>> (u0, u1), (v0, v1) = s.domain
    >>> s.points((u0 + u1) / 2, (v0 + v1) / 2).round(12).tolist()
    [1.0, 1.0, 0.5]
    """

    occt_construct = "Geom_BSplineSurface (Coons patch; cf. GeomFill_BSplineCurves CoonsStyle)"

    def occt_fill(self):
        """OCCT's ``GeomFill_BSplineCurves(c0, d1, c1 reversed, d0 reversed, CoonsStyle)``
        as a ``Geom_BSplineSurface``; OCCT needs at least 4 poles per direction."""
        from ..occ.filling import bspline_curves_fill, reversed_curve

        c0, c1, d0, d1 = (c.to_bspline().geom() for c in self.boundaries)
        return bspline_curves_fill(c0, d1, reversed_curve(c1), reversed_curve(d0), "coons")


def _corner_check(curves, tolerance):
    """Each of the four corners must be shared by the two curves meeting there."""
    ends = {name: c.points(np.array(c.domain)) for name, c in zip(NAMES, curves)}
    corners = (
        ("c0", 0, "d0", 0, "S(u0, v0)"),
        ("c0", 1, "d1", 0, "S(u1, v0)"),
        ("c1", 0, "d0", 1, "S(u0, v1)"),
        ("c1", 1, "d1", 1, "S(u1, v1)"),
    )
    which = ("start", "end")
    for a, ia, b, ib, label in corners:
        gap = float(np.linalg.norm(ends[a][ia] - ends[b][ib]))
        if gap > tolerance:
            raise SurfmodError(
                f"{b}: its {which[ib]} is {gap:.3g} away from the {which[ia]} of {a}; the boundary "
                f"curves must meet at the corner {label} (c0/c1 run along u at v0/v1, d0/d1 along v at u0/u1)"
            )


def _hermite_coefficients(n):
    """OCCT's ``GeomFill_Coons`` blend coefficients ``(F, G)`` for ``n`` poles."""
    # the cubic Hermite blend 1 - 3s^2 + 2s^3 in Bernstein form, raised to degree n - 1
    f = elevate_degree(np.repeat([0.0, 1.0], 4), 3, np.array([1.0, 1.0, 0.0, 0.0]), n - 4)[1]
    return f, 1.0 - f


def _scaled_weights(curves):
    """Homogeneous control arrays with weights scaled so corner weights agree."""
    w = [c.weights if c.weights is not None else np.ones(len(c.control_points)) for c in curves]
    w0, w1, wd0, wd1 = w
    a = 1.0 / w0[0]
    d = a * w0[0] / wd0[0]
    b = a * w0[-1] / wd1[0]
    c = d * wd0[-1] / w1[0]
    if abs(c * w1[-1] - b * wd1[-1]) > 1e-12 * max(c * w1[-1], b * wd1[-1]):
        raise SurfmodError(
            "c1: the end weights of the four rational boundaries cannot be matched at the corners "
            "(w_c0(0) w_d1(0) w_c1(1) w_d0(1) must equal w_c0(1) w_d1(1) w_c1(0) w_d0(0)); "
            "reparametrize the curves so their end weights are 1"
        )
    return [homogeneous(cv.control_points, wt * s) for cv, wt, s in zip(curves, w, (a, c, d, b))]


def coons(c0, c1, d0, d1, *, blend: str = "linear", tolerance: float = 1e-7) -> CoonsSurface:
    """The Coons patch bounded by four curves (surfmod curves or build123d Edges/Wires).

    ``c0``/``c1`` are the boundaries at ``v = v0``/``v1`` (running in ``u``), ``d0``/``d1``
    those at ``u = u0``/``u1`` (running in ``v``); the curves must meet at the four
    corners within ``tolerance`` (``c0`` starts where ``d0`` starts, ``c0`` ends where
    ``d1`` starts, ``c1`` starts where ``d0`` ends, ``c1`` ends where ``d1`` ends).
    ``blend`` is ``"linear"`` (bilinearly blended Coons patch) or ``"hermite"`` (OCCT's
    ``GeomFill_Coons`` blending).  The result interpolates all four curves exactly.

    >>> import surfmod as sm, numpy as np
    >>> c0 = sm.BSplineCurve([(0, 0, 0), (1, 0, 1), (2, 0, 0)], 2)
    >>> c1 = sm.BSplineCurve([(0, 2, 0), (1, 2, -1), (2, 2, 0)], 2)
    >>> d0 = sm.Line((0, 0, 0), (0, 2, 0)); d1 = sm.Line((2, 0, 0), (2, 2, 0))
    >>> s = sm.coons(c0, c1, d0, d1)
    >>> bool(np.allclose(s.points(0.3, 0.0), c0.points(0.3)))
    True
    """
    if blend not in BLENDS:
        raise SurfmodError(f"blend: expected one of {BLENDS}, got {blend!r}")

    tolerance = checks.positive(tolerance, "tolerance")
    given = [as_curve(c, name) for c, name in zip((c0, c1, d0, d1), NAMES)]
    ends = np.concatenate([c.points(np.array(c.domain)) for c in given])
    tolerance = checks.tolerance(tolerance, "tolerance", float(np.linalg.norm(np.ptp(ends, axis=0))))
    _corner_check(given, tolerance)

    # as OCCT's SetSameDistribution: the longer interval wins, ties go to c0 and to d1
    cu = make_compatible([given[0].to_bspline(), given[1].to_bspline()])
    cv = make_compatible([given[3].to_bspline(), given[2].to_bspline()])[::-1]
    if blend == "hermite":  # OCCT's cubic blend needs at least 4 poles per direction
        cu = _at_least_cubic(cu)
        cv = _at_least_cubic(cv)
    curves = [cu[0], cu[1], cv[0], cv[1]]
    rational = any(c.weights is not None for c in curves)
    if rational:
        h0, h1, hd0, hd1 = _scaled_weights(curves)
    else:
        h0, h1, hd0, hd1 = (c.control_points for c in curves)
    n, m = len(h0), len(hd0)
    if blend == "linear":
        # 1 - s at the Greville abscissae, s running over [0, 1] on the domain
        fu, fv = (1.0 - (greville(c.knots, c.degree) - c.domain[0]) / (c.domain[1] - c.domain[0])
                  for c in (cu[0], cv[0]))
        gu, gv = 1.0 - fu, 1.0 - fv
    else:
        fu, gu = _hermite_coefficients(n)
        fv, gv = _hermite_coefficients(m)
    p00, p10, p01, p11 = hd0[0], hd1[0], hd0[-1], hd1[-1]
    net = (
        fv[None, :, None] * h0[:, None, :] + gv[None, :, None] * h1[:, None, :]
        + fu[:, None, None] * hd0[None, :, :] + gu[:, None, None] * hd1[None, :, :]
        - (fu[:, None] * fv[None, :])[..., None] * p00 - (gu[:, None] * fv[None, :])[..., None] * p10
        - (fu[:, None] * gv[None, :])[..., None] * p01 - (gu[:, None] * gv[None, :])[..., None] * p11
    )
    # the boundaries are the curves' own poles (the d curves win at the corners, as OCCT)
    net[:, 0], net[:, -1] = h0, h1
    net[0, :], net[-1, :] = hd0, hd1
    pts, w = cartesian(net, rational)
    if w is not None and np.any(w <= 0):
        raise SurfmodError("c0: the blended weights are not positive; use boundaries with end weights 1")
    obj = CoonsSurface._trusted(pts, (cu[0].degree, cv[0].degree), (cu[0].knots, cv[0].knots), w)
    obj.boundaries = tuple(given)
    obj.blend = blend
    return obj


def _at_least_cubic(pair):
    if len(pair[0].control_points) >= 4:
        return pair
    deg = pair[0].degree + 4 - len(pair[0].control_points)
    return [elevated(c, deg) for c in pair]
