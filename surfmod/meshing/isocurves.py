"""The lecture's "mesh of curves": constant-u and constant-v curves of a surface.

Every iso-curve is an *exact* curve: for B-spline / NURBS / Bézier surfaces the
iso-parametric B-spline (``BSplineSurface.isocurve``, equal to OCCT's ``UIso``/``VIso``);
for any other surface an :class:`IsoCurve` that evaluates the surface itself with one
parameter fixed, whose OCCT twin is ``Geom_Surface::UIso``/``VIso`` with the same
parametrization.  ``IsoCurves.polylines(samples)`` gives the arrays for drawing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import checks
from ..construct.from_edge import from_edge
from ..curve import Curve
from ..errors import SurfmodError
from ..readback import surface_of
from ..surface import Surface, require_surface


class IsoCurve(Curve):
    """The curve ``t -> S(value, t)`` (``direction=0``: u fixed) or ``t -> S(t, value)``
    (``direction=1``: v fixed) of a surface, evaluated exactly through the surface.

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 0), (2, 0, 0), (0, 3, 0))
    >>> IsoCurve(s, 0, 0.5).points(1.0)
    array([1., 3., 0.])
    """

    occt_construct = "Geom_Surface.UIso/VIso"

    def __init__(self, surface: Surface, direction: int, value: float):
        surface = require_surface(surface, "surface")
        if direction not in (0, 1):
            raise SurfmodError(f"direction: must be 0 (u fixed) or 1 (v fixed), got {direction!r}")
        name = "u" if direction == 0 else "v"
        self.value = float(checks.parameters(np.asarray(float(value)), name, surface.domain[direction]))
        self.surface, self.direction = surface, direction
        self.exact_in_occt = bool(getattr(surface, "exact_in_occt", True))

    @property
    def domain(self):
        return self.surface.domain[1 - self.direction]

    def _derivatives(self, t, order):
        fixed = np.full_like(t, self.value)
        if self.direction == 0:
            d = self.surface._derivatives(fixed, t, order)
            return d[:, 0, :, :]
        d = self.surface._derivatives(t, fixed, order)
        return d[:, :, 0, :]

    def geom(self):
        from ..occ.geom import iso_curve

        return iso_curve(self.surface.geom(), self.direction, self.value)

    def transformed(self, matrix) -> "IsoCurve":
        return IsoCurve(self.surface.transformed(matrix), self.direction, self.value)

    def to_bspline(self):
        if hasattr(self.surface, "isocurve"):
            return _spline_iso(self.surface, self.direction, self.value)
        return from_edge(self.edge())


def _spline_iso(s, direction: int, value: float):
    return s.isocurve(**{"uv"[direction]: value})


@dataclass(frozen=True)
class IsoCurves:
    """Constant-u curves (``u_curves[i]`` at ``u_values[i]``, each a curve in v) and
    constant-v curves (``v_curves[j]`` at ``v_values[j]``, each a curve in u).

    ``exact`` says the curves are B-splines equal to the surface's iso-curves (B-spline
    surfaces); otherwise they are :class:`IsoCurve` objects evaluating the surface.

    >>> import surfmod as sm
    >>> iso = sm.isocurves(sm.BezierSurface([[(0, 0, 0), (0, 1, 0)], [(1, 0, 0), (1, 1, 1)]]), 3, 2)
    >>> iso.exact, len(iso.u_curves), len(iso.v_curves)
    (True, 3, 2)
    """

    surface: Surface
    u_values: np.ndarray
    v_values: np.ndarray
    u_curves: tuple
    v_curves: tuple
    exact: bool

    def polylines(self, samples: int = 64):
        """``(u_lines, v_lines)``: arrays ``(nu, samples, 3)`` and ``(nv, samples, 3)`` of
        points along the constant-u and constant-v curves (one tensor-grid evaluation).

        >>> import surfmod as sm
        >>> iso = sm.isocurves(sm.plane((0, 0, 0), (1, 0, 0), (0, 1, 0)), 3, 2)
        >>> [a.shape for a in iso.polylines(5)]
        [(3, 5, 3), (2, 5, 3)]
        """
        samples = checks.count(samples, "samples", minimum=2)
        (u0, u1), (v0, v1) = self.surface.domain
        s = self.surface
        ul = s.grid(self.u_values, np.linspace(v0, v1, samples)) if self.u_values.size else np.zeros((0, samples, 3))
        vl = s.grid(np.linspace(u0, u1, samples), self.v_values) if self.v_values.size else np.zeros((samples, 0, 3))
        return ul, vl.transpose(1, 0, 2)

    def edges(self):
        """All iso-curves as build123d ``Edge`` objects (OCCT's exact counterparts)."""
        return [c.edge() for c in (*self.u_curves, *self.v_curves)]


def isocurves(s, nu: int, nv: int) -> IsoCurves:
    """The ``nu`` constant-u and ``nv`` constant-v curves of ``s``, equally spaced in
    parameter and including the domain boundaries (``nu, nv >= 2``; 0 skips a family).

    ``s`` is a surfmod surface or a build123d ``Face`` (read with ``sm.from_face``).

    >>> import numpy as np, surfmod as sm
    >>> net = np.zeros((4, 4, 3)); net[..., 0], net[..., 1] = np.mgrid[0:4, 0:4]
    >>> iso = sm.isocurves(sm.BSplineSurface(net, (3, 3)), 5, 3)
    >>> len(iso.u_curves), len(iso.v_curves), iso.exact
    (5, 3, True)
    >>> iso.u_curves[2].points(0.5)
    array([1.5, 1.5, 0. ])
    """
    s = surface_of(s, "s")
    counts = []
    for value, name in ((nu, "nu"), (nv, "nv")):
        n = checks.count(value, name, minimum=0)
        if n == 1:
            raise SurfmodError(f"{name}: must be 0 or >= 2 (the curves include both domain ends), got 1")
        counts.append(n)
    (u0, u1), (v0, v1) = s.domain
    us = np.linspace(u0, u1, counts[0])
    vs = np.linspace(v0, v1, counts[1])
    exact = hasattr(s, "isocurve")
    make = _spline_iso if exact else IsoCurve
    uc = tuple(make(s, 0, float(u)) for u in us)
    vc = tuple(make(s, 1, float(v)) for v in vs)
    return IsoCurves(s, checks.frozen(us), checks.frozen(vs), uc, vc, exact)
