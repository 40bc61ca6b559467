"""splipy ⇄ surfmod: ``to_splipy``, ``from_splipy``.

splipy bases are ``BSplineBasis(order = degree + 1, knots)`` with full knot vectors;
control points are an ``(n1, n2, dim)`` array, homogeneous (weight last) when rational.
Periodic splipy bases are read through their non-periodic form (``lower_periodic``).
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve, BSplineSurface, homogeneous
from ..extras import require
from .common import from_homogeneous, nurbs_of


def to_splipy(obj):
    """A splipy ``Curve``/``Surface`` with the same orders, knots, control points, weights.

    >>> import surfmod as sm, numpy as np
    >>> c = sm.BSplineCurve([(0, 0, 0), (1, 2, 0), (3, 0, 1)], 2)
    >>> sp = sm.to_splipy(c)
    >>> sp.order(0), bool(np.allclose(sp(0.4), c.points(0.4)))
    (3, True)
    """
    splipy = require("splipy", "interop", "to_splipy")
    kind, b = nurbs_of(obj)
    ctrl = homogeneous(b.control_points, b.weights)
    if kind == "curve":
        basis = splipy.BSplineBasis(b.degree + 1, b.knots)
        return splipy.Curve(basis, np.array(ctrl), rational=b.rational, raw=True)
    bases = [splipy.BSplineBasis(p + 1, k) for p, k in zip(b.degree, b.knots)]
    return splipy.Surface(*bases, np.array(ctrl), rational=b.rational, raw=True)


def from_splipy(obj):
    """A surfmod ``BSplineCurve``/``BSplineSurface`` from a splipy curve or surface.

    >>> import splipy.surface_factory as sf, surfmod as sm
    >>> s = sm.from_splipy(sf.disc(r=2.0, type="square"))
    >>> s.rational, s.degree
    (True, (2, 2))
    """
    splipy = require("splipy", "interop", "from_splipy")

    if not isinstance(obj, (splipy.Curve, splipy.Surface)):
        raise SurfmodError(f"obj: expected a splipy Curve or Surface, got {type(obj).__name__}")
    if any(b.periodic >= 0 for b in obj.bases):
        obj = obj.clone()
        for d, b in enumerate(obj.bases):
            if b.periodic >= 0:
                obj.lower_periodic(-1, direction=d)
    ctrl = np.asarray(obj.controlpoints, dtype=float)
    dim = obj.dimension
    if dim not in (2, 3):
        raise SurfmodError(f"obj: splipy object of dimension {dim}; expected 2 or 3")
    if dim == 2:
        ctrl = np.insert(ctrl, 2, 0.0, axis=-1)
    pts, w = from_homogeneous(ctrl, True) if obj.rational else (ctrl[..., :3], None)
    degrees = [b.order - 1 for b in obj.bases]
    knots = [np.asarray(b.knots, dtype=float) for b in obj.bases]
    if isinstance(obj, splipy.Curve):
        return BSplineCurve(pts, degrees[0], knots[0], w)
    return BSplineSurface(pts, tuple(degrees), tuple(knots), w)
