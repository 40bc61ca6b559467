"""Tabulated cylinder: a planar curve translated along a direction.

``S(u, v) = C(u) + v D`` with ``D`` the unit direction and ``v`` in ``[0, length]``:
exactly ``Geom_SurfaceOfLinearExtrusion(C, D)`` (u = curve parameter, v = distance),
the face ``BRepPrimAPI_MakePrism`` builds from an edge.
"""

from __future__ import annotations

import numpy as np

from .. import checks, transforms
from ..curve import Curve
from ..errors import SurfmodError
from ..nets.bspline import BSplineSurface
from ..surface import Surface
from .from_edge import as_curve


def curve_plane_normal(curve: Curve, name: str = "curve"):
    """Unit normal of the plane of a planar curve, ``None`` for a straight curve;
    ``SurfmodError`` naming ``name`` when the curve is not planar."""
    ctrl = curve.to_bspline().control_points
    c = ctrl - ctrl.mean(axis=0)
    size = max(float(np.abs(c).max()), 1e-300)
    _, sv, vt = np.linalg.svd(c, full_matrices=False)
    if sv.size < 2 or sv[1] <= 1e-12 * size:
        return None
    if sv.size > 2 and sv[2] > 1e-9 * size:
        dev = float(np.abs(c @ vt[2]).max())
        raise SurfmodError(f"{name}: must be planar (control points leave their best plane by {dev:.3g})")
    return vt[2]


class TabulatedCylinder(Surface):
    """``Geom_SurfaceOfLinearExtrusion``: ``C(u) + v D``.  Build with :func:`tabulated_cylinder`.

    >>> import surfmod as sm
    >>> s = sm.tabulated_cylinder(sm.Circle((0, 0, 0), (0, 0, 1), 2.0), (0, 0, 1), 5.0)
    >>> [round(float(x), 12) for x in s.points(0.0, 5.0)]
    [2.0, 0.0, 5.0]
    """

    occt_construct = "Geom_SurfaceOfLinearExtrusion"

    @classmethod
    def _trusted(cls, curve: Curve, direction, v_range):
        obj = cls._construct_fast()
        obj.curve = curve
        obj.direction = checks.frozen(np.asarray(direction, float) / np.linalg.norm(direction))
        obj.v_range = (float(v_range[0]), float(v_range[1]))
        return obj

    @property
    def domain(self):
        return tuple(float(t) for t in self.curve.domain), self.v_range

    @property
    def length(self) -> float:
        return self.v_range[1] - self.v_range[0]

    def _derivatives(self, u, v, order):
        out = np.zeros((u.size, order + 1, order + 1, 3))
        out[:, :, 0] = self.curve._derivatives(u, order)
        out[:, 0, 0] += v[:, None] * self.direction
        if order >= 1:
            out[:, 0, 1] = self.direction
        return out

    def _grid_derivatives(self, us, vs, order):
        """Tensor grid: the curve is evaluated once per u."""
        out = np.zeros((us.size, vs.size, order + 1, order + 1, 3))
        out[:, :, :, 0] = self.curve._derivatives(us, order)[:, None]
        out[:, :, 0, 0] += vs[None, :, None] * self.direction
        if order >= 1:
            out[:, :, 0, 1] = self.direction
        return out

    def geom(self):
        from ..occ.analytic import extrusion

        return self._twin(lambda: extrusion(self.curve.geom(), self.direction))

    def transformed(self, matrix):
        """Similarity maps keep the construct (v scales by ``|s|``, like OCCT); other
        affine maps return the mapped B-spline form."""
        m = transforms.affine(matrix)
        if not transforms.is_similarity(m):
            return self.to_nurbs().transformed(m)
        d = transforms.apply_vectors(m, self.direction)
        s = float(np.linalg.norm(d))
        v0, v1 = self.v_range
        return TabulatedCylinder._trusted(self.curve.transformed(m), d / s, (v0 * s, v1 * s))

    def to_nurbs(self) -> BSplineSurface:
        """Exact B-spline form: the curve's B-spline (u) times a degree-1 segment (v)."""
        c = self.curve.to_bspline()
        v0, v1 = self.v_range
        net = np.stack([c.control_points + v0 * self.direction, c.control_points + v1 * self.direction], axis=1)
        w = None if c.weights is None else np.stack([c.weights, c.weights], axis=1)
        return BSplineSurface._trusted(net, (c.degree, 1), (c.knots, np.array([v0, v0, v1, v1])), w)


def tabulated_cylinder(curve, direction, length: float) -> TabulatedCylinder:
    """Translate a planar ``curve`` (surfmod curve or build123d Edge/Wire) along
    ``direction`` over ``length``: u = curve parameter, v = distance in ``[0, length]``.

    >>> import surfmod as sm
    >>> s = sm.tabulated_cylinder(sm.Circle((0, 0, 0), (0, 0, 1), 1.0), (0, 0, 1), 3.0)
    >>> s.points(0.0, 2.0)
    array([1., 0., 2.])
    """
    c = as_curve(curve, "curve")
    d = checks.direction(direction, "direction")
    h = checks.positive(length, "length")
    normal = curve_plane_normal(c, "curve")
    if normal is not None and abs(float(d @ normal)) < 1e-9:
        raise SurfmodError("direction: lies in the plane of the curve, the surface would be flat and degenerate")
    if normal is None:
        ctrl = c.to_bspline().control_points
        chord = ctrl[-1] - ctrl[0] if np.linalg.norm(ctrl[-1] - ctrl[0]) > 0 else ctrl[np.argmax(np.linalg.norm(ctrl - ctrl[0], axis=1))] - ctrl[0]
        if np.linalg.norm(np.cross(chord / np.linalg.norm(chord), d)) < 1e-9:
            raise SurfmodError("direction: parallel to the (straight) curve, the surface would be degenerate")
    return TabulatedCylinder._trusted(c, d, (0.0, h))
