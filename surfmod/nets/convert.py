"""The exact, clamped B-spline form of any surface that OCCT converts exactly.

Blends (:mod:`surfmod.ops.blend`) and offsets (:mod:`surfmod.construct.offset`) work on
the poles of both neighbours, so an analytic surface is first written as a B-spline.

>>> import surfmod as sm
>>> b = as_bspline_surface(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), "s")
>>> b.degree
(1, 1)
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..surface import Surface, require_surface
from .bspline import BSplineSurface


def as_bspline_surface(s: Surface, name: str) -> BSplineSurface:
    """An exact, clamped B-spline form of ``s`` (OCCT's ``GeomConvert`` for analytic
    surfaces; the parametrization may differ, the geometry and the side names do not)."""
    if isinstance(s, BSplineSurface):
        out = s.to_bspline()
        return out.segment(*out.domain) if not _clamped(out) else out
    s = require_surface(s, name)
    if not s.exact_in_occt:
        raise SurfmodError(f"{name}: {type(s).__name__} has no exact B-spline form (fit it first)")
    from ..occ.filling import bspline_over

    (u0, u1), (v0, v1) = s.domain
    data = bspline_over(s.geom(), (u0, u1, v0, v1))
    out = BSplineSurface(data["control_points"], data["degree"], data["knots"], data["weights"])
    corners = s.points(np.array([u0, u1, u0, u1]), np.array([v0, v0, v1, v1]))
    (a0, a1), (b0, b1) = out.domain
    mine = out.points(np.array([a0, a1, a0, a1]), np.array([b0, b0, b1, b1]))
    if not np.allclose(corners, mine, atol=1e-9 * max(1.0, np.ptp(corners).max())):
        raise SurfmodError(f"{name}: OCCT's B-spline conversion changed the parameter directions")
    return out


def _clamped(s: BSplineSurface) -> bool:
    ok = True
    for k, p, n in zip(s.knots, s.degree, s.control_points.shape[:2]):
        ok &= bool(np.all(k[: p + 1] == k[p]) and np.all(k[n:] == k[n]))
    return ok
