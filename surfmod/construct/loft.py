"""Lofted (skinned) surfaces through a list of section curves (:func:`loft`): the sections
made compatible, their control points interpolated across them; the surface passes
through every section exactly.  See :doc:`/guide/surfaces` (section "Coons, ruled and
lofted surfaces").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..eval.basis import basis_matrix
from ..inputs import build123d_face, build123d_shell
from ..nets.bspline import BSplineSurface, cartesian, homogeneous
from ..nets.elevate import make_compatible
from .fitting import averaging_knots
from .from_edge import as_curves


_MAX_DEGREE = 8  # BRepOffsetAPI_ThruSections default max degree


class LoftSurface(BSplineSurface):
    """A lofted surface: a B-spline through the sections (see :doc:`/guide/surfaces`
    (section "Coons, ruled and lofted surfaces")).

    Attributes: ``sections`` (the input curves), ``ruled``, ``section_parameters``
    (``v_k``), ``tolerance`` (pass threshold of the geometric cross-check, ``1e-4`` x
    size).  ``geom()`` is OCCT's ``ThruSections`` face surface when OCCT makes one face
    (smooth lofts, two-section ruled lofts); a ruled loft through more sections is
    compared with OCCT's multi-face shell by :meth:`occt_deviation`, and its ``geom()``
    is its exact spline twin.

    >>> import surfmod as sm
    >>> s = sm.loft([sm.Line((0, 0, 0), (1, 0, 0)), sm.Line((0, 1, 1), (1, 1, 1))], ruled=True)
    >>> s.degree, s.points(0.5, 0.5).tolist()
    ((1, 1), [0.5, 0.5, 0.5])
    """

    occt_construct = "BRepOffsetAPI_ThruSections"

    def _thru(self):
        cached = getattr(self, "_thru_cache", None)
        if cached is None:
            from ..occ.sweep import thru_sections

            secs = [(c.geom(), *c.domain) for c in (s.to_bspline() for s in self.sections)]
            cached = self._thru_cache = thru_sections(secs, ruled=self.ruled)
        return cached

    def thru_sections(self):
        """OCCT's lofted shell (a build123d ``Shell``)."""
        return build123d_shell(self._thru()[0])

    def geom(self):
        if self.exact_in_occt:
            return BSplineSurface.geom(self)
        from ..occ.topo import face_surface

        surf, bounds, _rev = face_surface(self._thru()[1][0])
        self.occ_bounds = bounds
        return surf

    def face(self):
        if self.exact_in_occt:
            return BSplineSurface.face(self)
        return build123d_face(self._thru()[1][0])

    def occt_deviation(self, samples: int = 24) -> float:
        """Max distance from a ``samples x samples`` grid of our points to OCCT's
        ``ThruSections`` shell (all its faces)."""
        from ..occ.sample import distances_to_face

        (u0, u1), (v0, v1) = self.domain
        pts = self.grid(np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)).reshape(-1, 3)
        return float(distances_to_face(self._thru()[0], pts).max())

    @property
    def tolerance(self) -> float:
        return self._tolerance


def _closed(curve, size):
    t0, t1 = curve.domain
    ends = curve.points(np.array([t0, t1]))
    return bool(np.linalg.norm(ends[1] - ends[0]) <= 1e-7 * max(size, 1.0))


def _area_vector(curve):
    t = np.linspace(*curve.domain, 257)
    p = curve.points(t)
    return 0.5 * np.sum(np.cross(p[:-1] - p.mean(axis=0), p[1:] - p.mean(axis=0)), axis=0)


def _check_orientation(curves):
    pts = np.concatenate([c.points(np.linspace(*c.domain, 17)) for c in curves])
    size = float(np.ptp(pts, axis=0).max())
    closed = [_closed(c, size) for c in curves]
    for k in range(1, len(curves)):
        if closed[k] != closed[0]:
            what = "closed" if closed[k] else "open"
            raise SurfmodError(
                f"sections[{k}]: is {what} while sections[0] is {'closed' if closed[0] else 'open'}; "
                "a loft needs all sections closed or all open"
            )
        a, b = curves[k - 1], curves[k]
        if closed[0]:
            if np.dot(_area_vector(a), _area_vector(b)) < 0:
                raise SurfmodError(f"sections[{k}]: runs the opposite way round to sections[{k - 1}] (reverse it)")
        else:
            pa = a.points(np.array(a.domain))
            pb = b.points(np.array(b.domain))
            same = np.linalg.norm(pa[0] - pb[0]) + np.linalg.norm(pa[1] - pb[1])
            flipped = np.linalg.norm(pa[0] - pb[1]) + np.linalg.norm(pa[1] - pb[0])
            if flipped < same:
                raise SurfmodError(f"sections[{k}]: runs opposite to sections[{k - 1}] (its start is nearer the other's end)")
    return size


def loft(sections, *, ruled: bool = False) -> LoftSurface:
    """The lofted surface through ``sections`` (two or more curves or build123d edges).

    >>> import surfmod as sm, numpy as np
    >>> a = sm.BSplineCurve([(0, 0, 0), (1, 1, 0), (2, 0, 0)], 2)
    >>> b = sm.BSplineCurve([(0, 0, 2), (1, -1, 2), (2, 0, 2)], 2)
    >>> c = sm.BSplineCurve([(0, 0, 4), (1, 1, 4), (2, 0, 4)], 2)
    >>> s = sm.loft([a, b, c])
    >>> v = s.section_parameters
    >>> bool(np.allclose(s.points(0.5, v[1]), b.points(0.5)))
    True
    """
    curves = as_curves(sections, "sections", "a loft")
    size = _check_orientation(curves)

    compat = make_compatible(curves)
    rational = any(c.weights is not None for c in compat)
    hs = np.stack(
        [homogeneous(c.control_points, c.weights if c.weights is not None else (np.ones(len(c.control_points)) if rational else None)) for c in compat]
    )  # (K, n, dim)
    k_sec = hs.shape[0]
    # chord length between whole (homogeneous) control polygons, Frobenius norm: how
    # OCCT's ThruSections (GeomFill_AppSurf, Approx_ChordLength) parametrizes sections
    d = np.sqrt(np.sum(np.diff(hs, axis=0) ** 2, axis=(1, 2)))  # (K-1,)
    if np.any(d <= 1e-12 * max(size, 1.0)):
        k = int(np.argmax(d <= 1e-12 * max(size, 1.0))) + 1
        raise SurfmodError(f"sections[{k}]: coincides with sections[{k - 1}]")
    v = np.concatenate([[0.0], np.cumsum(d)]) / d.sum()
    # one polynomial piece of degree K-1 up to OCCT's max degree 8 (OCCT's ThruSections
    # interpolates exactly then); beyond, OCCT approximates and we skin bicubically
    q = 1 if ruled else (k_sec - 1 if k_sec - 1 <= _MAX_DEGREE else 3)
    kv = averaging_knots(v, q)

    b = basis_matrix(kv, q, k_sec, v)[0]
    ctrl = np.linalg.solve(b, hs.reshape(k_sec, -1)).reshape(hs.shape)  # (K, n, dim)
    net_h = ctrl.transpose(1, 0, 2)
    net, w = cartesian(net_h, rational)
    if w is not None and np.any(w <= 0):
        raise SurfmodError("sections: the interpolated weights are not positive; use sections with equal weights")
    obj = LoftSurface._trusted(net, (compat[0].degree, q), (compat[0].knots, kv), w)
    obj.sections = tuple(curves)
    obj.ruled = bool(ruled)
    obj.section_parameters = checks.frozen(v)
    obj.exact_in_occt = bool(ruled and k_sec > 2)
    obj._tolerance = 1e-4 * max(size, 1.0)
    return obj
