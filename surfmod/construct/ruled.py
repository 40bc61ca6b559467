"""Ruled surface between two curves (:func:`ruled`), ``S(u, v) = (1 - v) G(u) + v Q(u)``,
built pole for pole as OCCT's ``GeomFill`` builds it (rational curves with different
weights included).  See :doc:`/guide/surfaces` (section "Coons, ruled and lofted surfaces").
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface
from ..nets.elevate import make_compatible
from .from_edge import as_curve


def _occt_weights(c: BSplineCurve):
    """Weights as OCCT keeps them: None when all equal, else scaled to mean 1."""
    if c.weights is None or np.allclose(c.weights, c.weights[0], rtol=0, atol=0):
        return None
    return c.weights / c.weights.mean()


class RuledSurface(BSplineSurface):
    """A ruled B-spline surface of degree ``(p, 1)``; ``g`` and ``q`` are the two
    compatible boundary curves (``v = 0`` and ``v = 1``).  Build with :func:`ruled`.

    >>> import surfmod as sm
    >>> s = sm.ruled(sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((0, 1, 1), (1, 1, 1)))
    >>> s.degree, s.points(0.5, 0.5)
    ((1, 1), array([0.5, 0.5, 0.5]))
    """

    occt_construct = "Geom_BSplineSurface (GeomFill ruled, degree p x 1)"

    def occt_ruled(self):
        """OCCT's own ``GeomFill::Surface`` built from the two input curves' B-spline
        forms (for the parametric cross-check against OCCT's construction)."""
        from ..occ.analytic import ruled as occ_ruled

        return occ_ruled(self.inputs[0].geom(), self.inputs[1].geom())


def ruled(g, q) -> RuledSurface:
    """The ruled surface ``(1 - v) G(u) + v Q(u)`` between two curves (surfmod curves or
    build123d Edges/Wires), as OCCT's ruled B-spline (``GeomFill``).

    >>> import surfmod as sm
    >>> s = sm.ruled(sm.Line((0, 0, 0), (2, 0, 0)), sm.Line((0, 1, 1), (2, 1, 1)))
    >>> s.points(1.0, 0.5)
    array([1. , 0.5, 0.5])
    """
    curves = [as_curve(g, "g").to_bspline(), as_curve(q, "q").to_bspline()]
    try:
        a, b = make_compatible(curves)
    except np.linalg.LinAlgError as exc:  # pragma: no cover - collocation is nonsingular
        raise SurfmodError(f"g: could not make the curves compatible ({exc})") from None
    if a.control_points.shape != b.control_points.shape:  # pragma: no cover - near-equal knots
        raise SurfmodError("q: knot vectors could not be merged with g's")
    wa, wb = _occt_weights(a), _occt_weights(b)
    net = np.stack([a.control_points, b.control_points], axis=1)
    weights = None
    if wa is not None or wb is not None:
        n = a.control_points.shape[0]
        weights = np.stack([np.ones(n) if wa is None else wa, np.ones(n) if wb is None else wb], axis=1)
    obj = RuledSurface._trusted(net, (a.degree, 1), (a.knots, np.array([0.0, 0.0, 1.0, 1.0])), weights)
    obj.g, obj.q = a, b
    obj.inputs = tuple(curves)
    return obj
