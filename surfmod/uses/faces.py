"""Per-face evaluators on the NumPy side, for quadrature and drop-cutting.

Every face of a shape becomes a :class:`Patch`: its parameter box, its outward sign, the
break points of its parametrization (knots; quarter turns on periodic directions) and
an ``evaluate(u, v, order)`` returning ``(N, order+1, order+1, 3)`` partials.

* B-spline / Bézier faces are read back with :func:`surfmod.from_face` and evaluated by
  the surfmod NumPy evaluator;
* planes, cylinders, cones, spheres and tori are evaluated by the closed forms below
  (same parametrization as OCCT's ``Geom_*`` classes);
* any other surface type (revolution, extrusion, offset, ...) falls back to a loop over
  OCCT ``D1``/``D2`` and says so in ``Patch.evaluator``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import numpy as np

from ..errors import SurfmodError


@dataclass(frozen=True)
class Patch:
    index: int
    kind: str
    bounds: tuple
    sign: float
    natural: bool
    breaks_u: np.ndarray
    breaks_v: np.ndarray
    evaluator: str
    evaluate: object = field(repr=False)
    face: object = field(repr=False, default=None)


def _trig_derivative(k: int, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """k-th derivative of (cos u, sin u)."""
    c, s = np.cos(u), np.sin(u)
    return [(c, s), (-s, c), (-c, -s), (s, -c)][k % 4]


def _rho_zeta(kind: str, e: dict, v: np.ndarray, l: int):
    """l-th v-derivative of the radial and axial profile functions."""
    zero, one = np.zeros_like(v), np.ones_like(v)
    if kind == "Geom_CylindricalSurface":
        rho = e["radius"] * one if l == 0 else zero
        zeta = v if l == 0 else (one if l == 1 else zero)
    elif kind == "Geom_ConicalSurface":
        sa, ca = np.sin(e["angle"]), np.cos(e["angle"])
        rho = e["radius"] + v * sa if l == 0 else (sa * one if l == 1 else zero)
        zeta = v * ca if l == 0 else (ca * one if l == 1 else zero)
    elif kind == "Geom_SphericalSurface":
        c, s = _trig_derivative(l, v)
        rho, zeta = e["radius"] * c, e["radius"] * s
    else:  # torus
        c, s = _trig_derivative(l, v)
        rho = (e["major"] if l == 0 else 0.0) + e["minor"] * c
        zeta = e["minor"] * s
    return rho, zeta


def elementary_evaluator(kind: str, e: dict):
    """``evaluate(u, v, order)`` for an OCCT elementary surface (NumPy closed forms)."""
    o, x, y, z = e["origin"], e["x"], e["y"], e["z"]

    if kind == "Geom_Plane":
        def plane(u, v, order):
            out = np.zeros((len(u), order + 1, order + 1, 3))
            out[:, 0, 0] = o + u[:, None] * x + v[:, None] * y
            if order >= 1:
                out[:, 1, 0], out[:, 0, 1] = x, y
            return out
        return plane

    def revolved(u, v, order):
        out = np.zeros((len(u), order + 1, order + 1, 3))
        for k in range(order + 1):
            cu, su = _trig_derivative(k, u)
            radial = cu[:, None] * x + su[:, None] * y
            for l in range(order + 1):
                rho, zeta = _rho_zeta(kind, e, v, l)
                out[:, k, l] = rho[:, None] * radial
                if k == 0:
                    out[:, k, l] += zeta[:, None] * z
        out[:, 0, 0] += o
        return out

    return revolved


def _breaks(lo: float, hi: float, knots, periodic_piece: float | None) -> np.ndarray:
    pts = [lo, hi]
    if knots is not None:
        pts.extend(k for k in knots if lo < k < hi)
    if periodic_piece is not None:
        n = int(np.ceil((hi - lo) / periodic_piece - 1e-9))
        pts.extend(np.linspace(lo, hi, max(n, 1) + 1))
    b = np.unique(np.asarray(pts, dtype=float))
    keep = np.concatenate([[True], np.diff(b) > 1e-12 * max(1.0, hi - lo)])
    return b[keep]


_ANGULAR_U = {"Geom_CylindricalSurface", "Geom_ConicalSurface", "Geom_SphericalSurface",
              "Geom_ToroidalSurface", "Geom_SurfaceOfRevolution"}
_ANGULAR_V = {"Geom_SphericalSurface", "Geom_ToroidalSurface"}


def patch_of(rec: dict) -> Patch:
    """The :class:`Patch` for one face record of ``surfmod.occ.uses.face_records``."""
    from ..occ import uses as occ

    kind, (u0, u1, v0, v1) = rec["kind"], rec["bounds"]
    evaluate, how = None, "occt"
    if rec["elementary"] is not None:
        evaluate, how = elementary_evaluator(kind, rec["elementary"]), "numpy"
    elif kind in ("Geom_BSplineSurface", "Geom_BezierSurface"):
        try:
            from ..construct.from_face import from_face

            surf = from_face(rec["face"])
            evaluate, how = _surface_evaluator(surf), "numpy"
        except (SurfmodError, NotImplementedError, AttributeError):
            evaluate = None
    if evaluate is None:
        geom = rec["geom"]

        def evaluate(u, v, order, _g=geom):
            return occ.surface_derivatives(_g, u, v, order)

    knots = rec["knots"] or (None, None)
    piece = np.pi / 4
    bu = _breaks(u0, u1, knots[0], piece if kind in _ANGULAR_U else None)
    bv = _breaks(v0, v1, knots[1], piece if kind in _ANGULAR_V else None)
    return Patch(rec["index"], kind, rec["bounds"], -1.0 if rec["reversed"] else 1.0, rec["natural"],
                 bu, bv, how, evaluate, rec["face"])


def _surface_evaluator(surf):
    (su0, su1), (sv0, sv1) = surf.domain

    def evaluate(u, v, order):
        return surf._derivatives(np.clip(u, su0, su1), np.clip(v, sv0, sv1), order)

    return evaluate


def surface_patch(surf, index: int = 0) -> Patch:
    """A :class:`Patch` for a surfmod surface over its whole domain (NumPy evaluator)."""
    (u0, u1), (v0, v1) = surf.domain
    ku = getattr(surf, "knots", None)
    knots = ku if isinstance(ku, tuple) and len(ku) == 2 else (None, None)
    # analytic surfaces (no knots): eight pieces per direction keep Gauss converged
    pu = None if knots[0] is not None else (u1 - u0) / 8
    pv = None if knots[1] is not None else (v1 - v0) / 8
    return Patch(index, type(surf).__name__, (u0, u1, v0, v1), 1.0, True,
                 _breaks(u0, u1, knots[0], pu), _breaks(v0, v1, knots[1], pv),
                 "numpy", _surface_evaluator(surf), None)


def patches(shape) -> list[Patch]:
    """Patches for every face of an OCCT shape."""
    from ..occ import uses as occ

    return [patch_of(r) for r in occ.face_records(shape)]

