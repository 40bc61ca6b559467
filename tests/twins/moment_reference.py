"""An independent reference for the first and second moments of a solid, built only on
volumes (the one quantity surfmod's quadrature and ``BRepGProp`` already agree on).

Per unit direction ``a`` let ``V(t)`` be the volume of the solid cut by the half-space
``a·x <= t``.  Then ``V'(t)`` is the cross-section area and, integrating by parts between
the solid's lowest and highest levels ``t0 <= t <= t1`` (``h = t - c`` heights from a
centre ``c``)::

    ∫ h dV  = h1 V - ∫ V(t) dt
    ∫ h² dV = h1² V - 2 ∫ h V(t) dt

``V(t)`` is smooth between the *critical levels* of the height ``a·x`` on the boundary:
the vertices, the extreme points of edges (``C'·a = 0``), the interior critical points of
faces (``S_u·a = S_v·a = 0``: a plane normal to ``a``, the extreme generators of a
cylinder lying across ``a``, the poles of spheres and tori, a cone's apex; B-spline and
other faces by Newton from a grid).  At such a level ``V`` has one-sided expansions in
powers of ``sqrt(t - t*)`` (an edge's extreme point, a fold) or ``(t - t*)^k log`` (a
saddle), so each interval between two levels is mapped by ``t = a + (b - a) ψ(s)``,
``ψ(s) = 3s² - 2s³`` (``ψ ~ s²`` at both ends turns the half-integer powers into integer
ones, and a polynomial stays one) and integrated by Gauss–Kronrod (10 Gauss nodes inside
21 Kronrod nodes: the Kronrod sum is the result, QUADPACK's scaling of its difference
from the Gauss sum the error estimate).  Nodes keep clear of each level by twice the
tolerance of the sub-shapes there (the Boolean would take a nearer plane for the
feature): an interval too short for that after ψ is integrated without ψ, a shorter one
merged.

Each interval's 21 levels are cut at once: ``BRepAlgoAPI_Splitter`` cuts the solid by
their planes into slabs, and ``V(t)`` is not weighed as the volume of the slabs below
``t`` but as the flux of ``F = (a·x - t) a`` (divergence 1) through the solid's *own*
faces below ``t`` (their pieces, per slab, by ``BRepGProp``'s adaptive Gauss–Kronrod rule
at relative tolerance 1e-12).  The planar section faces drop out (``F`` vanishes on the
plane at ``t``, and the sections below are shared by two slabs with opposite normals);
the pieces of one curved face share the p-curves of the new edges between them, so only
the p-curve at ``t`` bounds a domain, and there ``F·n`` vanishes: a p-curve that OCCT
approximated ``δ`` off the true section (an ellipse on a cylinder cut obliquely, a circle
on a tilted sphere, any section of a torus or B-spline; ``δ ~ 1e-7``) moves ``V`` by
``δ²``, where the slabs' volumes moved by ``δ`` (1e-9..1e-8 of the part).  ``V`` at a
node is that sum below it, averaged with ``V`` minus the sum above.  The total flux of
all pieces against the solid's volume is that cut's *defect*, what the Boolean lost (each
piece is put in its slab by its centre of mass): a cut with a defect above 1e-10 is
tried again (axis-aligned boxes instead of oriented ones, then the odd and even nodes
apart), and the defect enters the error estimate as a volume misplaced over the interval.
A piece the splitter leaves uncut across a plane (seen on a rotated torus) moves volume
between slabs without a defect; ``V(t)`` is then no longer smooth there, and the
Gauss–Kronrod estimate is what shows it.

Second moments about a point: the three axes give ``∫h_i`` and ``∫h_i²``; the products
``∫h_i h_j`` come from three more sweeps along the diagonals ``(e_i + e_j)/√2``:
``∫(u·h)² = (∫h_i² + ∫h_j²)/2 + ∫h_i h_j`` (rotated axes rather than cuts along two axes:
cuts along two axes make ``V(s, t)`` singular along the solid's silhouette, a curve in
the ``(s, t)`` plane no tensor rule follows; six one-dimensional sweeps are exact between
levels, and the diagonals' first moments, which must equal ``(∫h_i + ∫h_j)/√2``, check the
axes' for free).

What it does not see: an error in a face piece's flux that its neighbour's cancels
(none is known: the shared p-curves make the pieces tile each face exactly).  Measured
(tests/test_mass_reference.py, against closed forms, rotated and moved solids): a box with
a hole and a spherical cap to 1e-11 of the part (centroid) and 4e-11 (inertia), a cone
frustum 4e-11 and 5e-9 (two cuts the splitter botches next to a fold of its base circle,
within the estimate).  Cost: 21 planes per
interval, six directions, seconds per hundred planes on prismatic parts and far more where
sections are walked (tori, B-splines); a ``budget`` stops a run at the pace of its first
cuts (see :func:`sweep`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Splitter
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.GProp import GProp_GProps
from OCP.GeomAbs import (GeomAbs_C2, GeomAbs_Cone, GeomAbs_Cylinder, GeomAbs_Line, GeomAbs_Plane,
                         GeomAbs_Sphere, GeomAbs_Torus)
from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance
from OCP.TopAbs import TopAbs_SHAPE, TopAbs_VERTEX
from OCP.TopLoc import TopLoc_Location
from OCP.TopoDS import TopoDS
from OCP.gp import gp_Dir, gp_Pln, gp_Pnt, gp_Trsf, gp_Vec

from surfmod.errors import SurfmodError
from surfmod.occ.arrays import xyz
from surfmod.occ.guard import kernel
from surfmod.occ.topo import compound, explore, faces_of, geometric_edges, solids_of
from surfmod.occ.bindings import TopTools_ListOfShape

# Gauss–Kronrod 10/21 on [-1, 1] (QUADPACK's qk21): Kronrod nodes from the end inwards,
# the Gauss nodes every second one (odd indices), the centre last
_XK = np.array([0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
                0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
                0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
                0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
                0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0])
_WK = np.array([0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
                0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
                0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
                0.123491976262065851077600525452442, 0.134709217311473325928054001771707,
                0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
                0.149445554002916905664936468389821])
_WG = np.array([0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
                0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
                0.295524224714752870173892994651338])
#: the 21 Kronrod nodes on [-1, 1], ascending, their weights, and the 10-point Gauss
#: weights on the same nodes (zero on the Kronrod-only ones)
KRONROD_X = np.concatenate([-_XK[:-1], _XK[::-1]])
KRONROD_W = np.concatenate([_WK[:-1], _WK[::-1]])
GAUSS_W = np.zeros(21)
GAUSS_W[1::2] = np.concatenate([_WG, _WG[::-1]])

#: the first Kronrod node's place after ψ, as a fraction of its interval: a node must stay
#: this far from a critical level, so an interval shorter than (a few tolerances) / this
#: is merged into its neighbour (the Boolean would take its nearest plane for a face)
_FIRST_PLAIN = (1 - _XK[0]) / 2
_FIRST_NODE = 3 * _FIRST_PLAIN ** 2 - 2 * _FIRST_PLAIN ** 3
#: directions of the six sweeps: the axes, then the diagonals giving the products
DIRECTIONS = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0], [1, 0, 1], [0, 1, 1]]) / np.sqrt(
    [[1], [1], [1], [2], [2], [2]])
_PAIRS = ((0, 1), (0, 2), (1, 2))


@dataclass(frozen=True)
class Sweep:
    """One direction's integrals: ``first = ∫h dV``, ``second = ∫h² dV`` with ``h`` the
    height along ``direction`` above ``centre``, their error estimates (Gauss against
    Kronrod, plus the cut's defect as a misplaced volume), the critical levels, the
    number of cutting planes and the defect ``Σ slabs - V`` (absolute)."""

    direction: np.ndarray
    centre: float
    first: float
    second: float
    first_error: float
    second_error: float
    levels: np.ndarray
    planes: int
    defect: float
    pieces: int


@dataclass(frozen=True)
class MomentReference:
    """Volume (the trusted input), centroid and inertia tensor about the centroid (OCCT's
    convention, ``Ixy = -∫xy``) from volume sweeps, with estimated absolute errors of the
    centroid (largest coordinate) and inertia (largest entry), the largest cut defect
    relative to the volume, the diagonals' first-moment check relative to ``V L`` (``L``
    the cube root of the volume), the planes cut and the seconds taken."""

    volume: float
    centroid: np.ndarray
    inertia: np.ndarray
    centroid_error: float
    inertia_error: float
    defect: float
    consistency: float
    planes: int
    seconds: float
    sweeps: tuple = field(default=(), repr=False)


def _vertex_points(shape):
    """The vertices' points ``(n, 3)`` and tolerances ``(n,)``."""
    vs = [TopoDS.Vertex(v) for v in explore(shape, TopAbs_VERTEX)]
    pts = np.array([xyz(BRep_Tool.Pnt_s(v)) for v in vs], dtype=float).reshape(-1, 3)
    return pts, np.array([BRep_Tool.Tolerance_s(v) for v in vs], dtype=float)


def max_tolerance(shape) -> float:
    """The largest tolerance of any sub-shape (vertex, edge, face) of ``shape``."""
    with kernel("ShapeAnalysis_ShapeTolerance"):
        return float(ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1, TopAbs_SHAPE))


# -- critical levels -------------------------------------------------------------------
def _edge_samples(shape):
    """Per curved edge: ``(adaptor, parameters, first derivatives, tolerance)`` on a
    sample wide enough to bracket each extreme of ``C(t)·a`` (a few per smooth interval)."""
    out = []
    for _, edge, _faces in geometric_edges(shape):
        c = BRepAdaptor_Curve(edge)
        if c.GetType() == GeomAbs_Line:
            continue  # a segment's extremes are its vertices
        t0, t1 = c.FirstParameter(), c.LastParameter()
        n = min(400, max(24, 6 * c.NbIntervals(GeomAbs_C2) + 1))
        t = np.linspace(t0, t1, n)
        p, d1 = gp_Pnt(), gp_Vec()
        der = np.empty((n, 3))
        for k, tt in enumerate(t):
            c.D1(float(tt), p, d1)
            der[k] = d1.X(), d1.Y(), d1.Z()
        out.append((c, t, der, BRep_Tool.Tolerance_s(edge)))
    return out


def _edge_levels(samples, a: np.ndarray) -> list:
    """Heights of the interior extremes of every sampled edge along ``a`` (Newton on
    ``C'·a = 0`` inside each bracket where it changes sign, bisection when Newton leaves),
    as ``(height, edge tolerance)`` pairs."""
    levels = []
    p, d1, d2 = gp_Pnt(), gp_Vec(), gp_Vec()
    for c, t, der, tol in samples:
        g = der @ a
        scale = np.abs(der).max() + 1e-300
        for k in np.nonzero(np.sign(g[:-1]) * np.sign(g[1:]) < 0)[0]:
            lo, hi, glo = t[k], t[k + 1], g[k]
            x = 0.5 * (lo + hi)
            for _ in range(60):
                c.D2(float(x), p, d1, d2)
                gx = d1.X() * a[0] + d1.Y() * a[1] + d1.Z() * a[2]
                if abs(gx) <= 1e-15 * scale:
                    break
                if np.sign(gx) == np.sign(glo):
                    lo, glo = x, gx
                else:
                    hi = x
                h = d2.X() * a[0] + d2.Y() * a[1] + d2.Z() * a[2]
                step = x - gx / h if h else 0.5 * (lo + hi)
                x = step if lo < step < hi else 0.5 * (lo + hi)
                if hi - lo <= 1e-15 * (abs(t[-1]) + abs(t[0]) + 1):
                    break
            c.D0(float(x), p)
            levels.append((p.X() * a[0] + p.Y() * a[1] + p.Z() * a[2], tol))
    return levels


def _surface_grid(face):
    """``(adaptor, u, v, derivatives)`` of a face of a free-form (non-elementary) surface
    on a grid over its UV bounds: derivatives ``(nu, nv, 6, 3)`` = S, Su, Sv, Suu, Suv, Svv."""
    s = BRepAdaptor_Surface(face, False)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    nu = min(41, max(9, 3 * s.NbUIntervals(GeomAbs_C2) + 1))
    nv = min(41, max(9, 3 * s.NbVIntervals(GeomAbs_C2) + 1))
    u, v = np.linspace(u0, u1, nu), np.linspace(v0, v1, nv)
    out = np.empty((nu, nv, 6, 3))
    vecs = [gp_Pnt()] + [gp_Vec() for _ in range(5)]
    for i, uu in enumerate(u):
        for j, vv in enumerate(v):
            s.D2(float(uu), float(vv), *vecs)
            out[i, j] = [q.Coord() for q in vecs]
    return s, u, v, out


def _newton_critical(s, u, v, box, a, scale):
    """A critical point of ``S·a`` near ``(u, v)`` by Newton (least-squares steps, so a
    line of critical points is met too), or None when it leaves the face's UV ``box`` or
    does not converge."""
    u0, u1, v0, v1 = box
    vecs = [gp_Pnt()] + [gp_Vec() for _ in range(5)]
    for _ in range(40):
        s.D2(float(u), float(v), *vecs)
        d = np.array([q.Coord() for q in vecs]) @ a
        g = d[1:3]
        if np.abs(g).max() <= 1e-13 * scale:
            return d[0]
        hess = np.array([[d[3], d[4]], [d[4], d[5]]])
        step = np.linalg.lstsq(hess, -g, rcond=1e-12)[0]
        u, v = u + step[0], v + step[1]
        if not (u0 - 1e-9 <= u <= u1 + 1e-9 and v0 - 1e-9 <= v <= v1 + 1e-9):
            return None
    return None


def _face_levels(face_data, a: np.ndarray) -> tuple[list, int]:
    """Heights of the interior critical points of every face along ``a`` as ``(height,
    face tolerance)`` pairs, and how many grid cells held a sign change Newton could not
    settle (then the error estimate shows whether it mattered)."""
    out, unresolved = [], 0
    for kind, data, tol in face_data:
        levels = []
        if kind == "plane":
            n, p = data
            if abs(abs(n @ a) - 1) < 1e-12:
                levels.append(p @ a)
        elif kind == "cylinder":
            d, p, r = data
            if abs(d @ a) < 1e-12:
                levels += [p @ a - r, p @ a + r]
        elif kind == "cone":
            levels.append(data @ a)  # the apex (the only level where a cone can be critical)
        elif kind == "sphere":
            c, r = data
            levels += [c @ a - r, c @ a + r]
        elif kind == "torus":
            d, c, big, small = data
            ap = math.sqrt(max(0.0, 1 - float(d @ a) ** 2))
            levels += [c @ a + sb * big * ap + ss * small for sb in (-1, 1) for ss in (-1, 1)]
        else:
            s, u, v, grid = data
            g = grid[:, :, 1:3] @ a  # (nu, nv, 2)
            scale = float(np.abs(grid[:, :, 1:3]).max()) + 1e-300
            gu, gv = g[..., 0], g[..., 1]

            def mixed(x):  # cells whose four corners do not share one strict sign
                c = np.stack([x[:-1, :-1], x[1:, :-1], x[:-1, 1:], x[1:, 1:]])
                return (c.min(axis=0) <= 0) & (c.max(axis=0) >= 0)

            for i, j in zip(*np.nonzero(mixed(gu) & mixed(gv))):
                h = _newton_critical(s, 0.5 * (u[i] + u[i + 1]), 0.5 * (v[j] + v[j + 1]),
                                     (u[0], u[-1], v[0], v[-1]), a, scale)
                if h is None:
                    unresolved += 1
                else:
                    levels.append(h)
        out += [(h, tol) for h in levels]
    return out, unresolved


def _faces_data(shape):
    out = []
    for face in faces_of(shape):
        s = BRepAdaptor_Surface(face, False)
        kind = s.GetType()
        tol = BRep_Tool.Tolerance_s(face)
        if kind == GeomAbs_Plane:
            pl = s.Plane()
            out.append(("plane", (xyz(pl.Axis().Direction()), xyz(pl.Location())), tol))
        elif kind == GeomAbs_Cylinder:
            cy = s.Cylinder()
            out.append(("cylinder", (xyz(cy.Axis().Direction()), xyz(cy.Location()), cy.Radius()), tol))
        elif kind == GeomAbs_Cone:
            out.append(("cone", xyz(s.Cone().Apex()), tol))
        elif kind == GeomAbs_Sphere:
            sp = s.Sphere()
            out.append(("sphere", (xyz(sp.Location()), sp.Radius()), tol))
        elif kind == GeomAbs_Torus:
            to = s.Torus()
            frame = (xyz(to.Axis().Direction()), xyz(to.Location()), to.MajorRadius(), to.MinorRadius())
            out.append(("torus", frame, tol))
        else:
            out.append(("grid", _surface_grid(face), tol))
    return out


class _Levels:
    """The critical-level finder of one solid: samples its edges and free-form faces once
    and answers per direction."""

    def __init__(self, shape):
        with kernel("critical levels"):
            self.vertices = _vertex_points(shape)
            self.edges = _edge_samples(shape)
            self.faces = _faces_data(shape)
        self.unresolved = 0

    def along(self, a: np.ndarray, tolerances: bool = False):
        """The sorted critical levels along ``a`` (distinct), and with ``tolerances`` the
        largest tolerance of the sub-shapes at each (a vertex's, an edge's, a face's)."""
        with kernel("critical levels"):
            faces, unresolved = _face_levels(self.faces, a)
            self.unresolved += unresolved
            pairs = _edge_levels(self.edges, a) + faces
            pts, vtol = self.vertices
            levels = np.concatenate([pts @ a, [h for h, _ in pairs]])
            tols = np.concatenate([vtol, [t for _, t in pairs]])
        order = np.lexsort((-tols, levels))
        levels, tols = levels[order], tols[order]
        first = np.concatenate([[True], np.diff(levels) > 0])
        # the largest tolerance at each distinct level: sorted by level, then by tolerance
        # descending, the first of each run holds it
        return (levels[first], tols[first]) if tolerances else levels[first]


def critical_levels(shape, direction) -> np.ndarray:
    """The sorted heights along the unit vector ``direction`` at which the cut volume
    ``V(t)`` of ``shape`` may lose smoothness (vertices, edges' extremes, faces' critical
    points; see the module notes).  The first and last are the solid's extent.

    >>> import build123d as bd
    >>> critical_levels(bd.Sphere(2).wrapped, (0, 0, 1)).round(12).tolist()
    [-2.0, 2.0]
    """
    a = np.asarray(direction, dtype=float)
    return _Levels(shape).along(a / np.linalg.norm(a))


# -- intervals and nodes ---------------------------------------------------------------
def _intervals(levels: np.ndarray, min_length: float, pieces: int, tolerances=None):
    """Interval ends from the critical levels, and per interval whether it is mapped by ψ.

    Each interval is at least ``min_length`` long, and its nodes stay twice the
    ``tolerances`` of its two ends clear of them: mapped by ψ when its first node (1.4e-5
    of the length in) does, else integrated by plain Gauss–Kronrod (first node 2.2e-3 in:
    a short interval next to a loose vertex keeps its breakpoint, and its end behaviour
    costs little for being short); a level too close even for that is merged into the one
    before (which takes the larger tolerance).  The last level is always kept, the one
    before it dropped if too close.  Intervals longer than the extent / ``pieces`` are
    split evenly.  ``SurfmodError`` when not even the whole extent leaves that room."""
    tols = np.zeros(len(levels)) if tolerances is None else np.asarray(tolerances, dtype=float)

    def need(t0, t1, first=_FIRST_PLAIN):
        return max(min_length, 2 * max(t0, t1) / first)

    keep, ktol = [levels[0]], [tols[0]]
    for t, tol in zip(levels[1:-1], tols[1:-1]):
        if t - keep[-1] >= need(ktol[-1], tol):
            keep.append(t)
            ktol.append(tol)
        else:
            ktol[-1] = max(ktol[-1], tol)
    last, ltol = levels[-1], tols[-1]
    while len(keep) > 1 and last - keep[-1] < need(ktol[-1], ltol):
        keep.pop()
        ltol = max(ltol, ktol.pop())
    if last - keep[-1] < need(ktol[-1], ltol):
        raise SurfmodError(f"shape: its tolerances (up to {max(ltol, ktol[-1]):.1e}) leave no room for cuts clear of "
                           f"its features along this direction (extent {last - keep[-1]:.3g})")
    keep.append(last)
    ktol.append(ltol)
    ends, mapped = [keep[0]], []
    longest = (keep[-1] - keep[0]) / pieces
    for k in range(1, len(keep)):
        length = keep[k] - keep[k - 1]
        n = max(1, math.ceil(length / longest - 1e-9))
        ends += list(np.linspace(keep[k - 1], keep[k], n + 1)[1:])
        mapped += [length >= need(ktol[k - 1], ktol[k], _FIRST_NODE)] * n
    return np.array(ends), np.array(mapped, dtype=bool)


def _nodes(ends: np.ndarray, mapped=None):
    """Nodes ``(m, 21)`` of the intervals between ``ends`` after ``t = a + (b - a) ψ(s)``
    (or plainly where ``mapped`` is false) and the factors ``(b - a) ψ'(s) / 2`` that
    make ``∫ f dt`` the Kronrod (or Gauss) sum of ``f`` times them."""
    s = (KRONROD_X + 1) / 2
    psi, dpsi = 3 * s * s - 2 * s ** 3, 6 * s * (1 - s)
    mapped = np.ones(len(ends) - 1, dtype=bool) if mapped is None else np.asarray(mapped, dtype=bool)
    psi = np.where(mapped[:, None], psi, s)
    dpsi = np.where(mapped[:, None], dpsi, 1.0)
    length = np.diff(ends)[:, None]
    return ends[:-1, None] + length * psi, length * dpsi / 2


# -- cutting ---------------------------------------------------------------------------
#: BRepGProp's relative tolerance for the fluxes of the pieces' faces (its adaptive
#: Gauss–Kronrod rule; it reaches 1e-15 on elementary faces)
PIECE_EPS = 1e-12


def _quad_error(f: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """QUADPACK's error estimate of the 21-point Kronrod sum on each interval (``f`` the
    integrand at the nodes, ``scale`` the half lengths times ψ'): the Gauss–Kronrod
    difference ``d`` scaled as ``A min(1, (200 d / A)^1.5)`` (``A`` the Kronrod sum of
    ``|f - mean|``, how much the integrand varies), since the Kronrod sum's error falls
    much faster than the Gauss sum's; never below 50 ulps of ``∫|f|``."""
    g = f * scale
    k = g @ KRONROD_W
    d = np.abs(k - g @ GAUSS_W)
    mean = (k / np.maximum(scale @ KRONROD_W, 1e-300))[:, None]
    asc = (np.abs(f - mean) * scale) @ KRONROD_W
    ratio = np.where(asc > 0, 200 * d / np.where(asc > 0, asc, 1), 0.0)
    err = np.where(asc > 0, asc * np.minimum(1.0, ratio ** 1.5), d)
    return np.maximum(err, 50 * np.finfo(float).eps * (np.abs(g) @ KRONROD_W))


def _flux(shape, shift, a) -> float:
    """``∫ (a·(x - shift)) (a·n) dA`` over the faces of ``shape``: BRepGProp's volume
    "between the faces and a plane", for the plane through the origin normal to ``a``
    after moving the faces by ``-shift``.  (Moved rather than given a plane through
    ``shift``: OCCT 7.9's plane variant measures heights from the plane's mirror image
    about the origin, ``a·x + d`` for the plane ``a·x = d``; through the origin the two
    agree, tests/test_mass_reference.py pins it.)"""
    move = gp_Trsf()
    move.SetTranslation(gp_Vec(*(-np.asarray(shift, dtype=float))))
    props = GProp_GProps()
    BRepGProp.VolumePropertiesGK_s(shape.Moved(TopLoc_Location(move)), props,
                                   gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(*a)), PIECE_EPS)
    return props.Mass()


def _slab_of(piece, heights, a) -> int:
    """The slab (0 below the first height ... ``len(heights)`` above the last) holding a
    piece of the split solid, from its centre of mass.  (Not from its vertices: next to
    a fold of an edge the Boolean gives new vertices tolerances of 1e-5 and merges a
    sliver into its neighbour, and vertices then name slabs the volume is not in.)"""
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(piece, props, PIECE_EPS, False, False)
    return int(np.searchsorted(heights, a @ xyz(props.CentreOfMass())))


def _is_cut_face(face, a, heights, span) -> bool:
    """Whether ``face`` lies on one of the cutting planes (a plane normal to ``a`` at one
    of ``heights``: the nodes keep clear of the solid's own faces normal to ``a``)."""
    s = BRepAdaptor_Surface(face, False)
    if s.GetType() != GeomAbs_Plane:
        return False
    pl = s.Plane()
    if abs(abs(xyz(pl.Axis().Direction()) @ a) - 1) > 1e-12:
        return False
    return bool(np.abs(heights - xyz(pl.Location()) @ a).min() <= 1e-9 * span)


def cut_volumes(shape, direction, heights, volume: float, origin, size: float, obb: bool = True):
    """``V(t)`` at each of the sorted ``heights`` along ``direction``, returned as ``(V,
    defect, pieces)``.

    The solid is split by all their planes at once (``BRepAlgoAPI_Splitter``); then
    ``V(t)`` is the flux of ``F = (a·x - t) a`` (divergence 1) through the solid's own
    boundary below ``t``: the cut faces drop out (``F`` vanishes on the plane ``t`` and
    the faces of the planes below are shared by two slabs with opposite normals), and
    the pieces of one original face share the p-curves of the new edges between them, so
    only the p-curve at ``t`` itself bounds a domain, where ``F·n`` vanishes: a p-curve
    ``δ`` off (OCCT approximates them, ``δ ~ 1e-7``) moves ``V`` by ``δ²``, not ``δ``.
    Per slab (the slab of each piece, from its centre) the flux ``W`` about ``origin``
    and the projected area ``M = ∫a·n dA`` give ``V(t) = Σ_below (W - (t - c) M)``,
    averaged with ``V`` minus the same sum above.  ``defect`` is the total flux less
    ``volume`` (a piece the splitter lost or broke).  The planes are squares of half
    side ``size`` about ``origin``'s projections (the part's centre: they need only cover it)."""
    a = np.asarray(direction, dtype=float)
    heights = np.asarray(heights, dtype=float)
    origin = np.asarray(origin, dtype=float)
    centre = float(a @ origin)
    span = float(heights[-1] - heights[0]) if len(heights) > 1 else size
    with kernel("BRepAlgoAPI_Splitter"):
        tools = TopTools_ListOfShape()
        for h in heights:
            plane = gp_Pln(gp_Pnt(*(origin + a * (h - centre))), gp_Dir(*a))
            tools.Append(BRepBuilderAPI_MakeFace(plane, -size, size, -size, size).Face())
        args = TopTools_ListOfShape()
        args.Append(shape)
        splitter = BRepAlgoAPI_Splitter()
        splitter.SetArguments(args)
        splitter.SetTools(tools)
        splitter.SetRunParallel(False)
        splitter.SetUseOBB(obb)
        # the caller's solid stays as it was (the Boolean may otherwise raise the
        # tolerances of its sub-shapes in place)
        splitter.SetNonDestructive(True)
        splitter.Build()
        if not splitter.IsDone():
            raise SurfmodError("shape: OCCT's splitter failed to cut the solid into slabs")
        pieces = solids_of(splitter.Shape())
        slab_faces = [[] for _ in range(len(heights) + 1)]
        for piece in pieces:
            slab_faces[_slab_of(piece, heights, a)].extend(
                face for face in faces_of(piece) if not _is_cut_face(face, a, heights, span))
        slabs = [compound(faces) for faces in slab_faces]
        # the second reference level a half side away: M from the difference of two
        # fluxes loses only log10(size / slab) digits
        w = np.array([_flux(c, origin, a) for c in slabs])
        m = (w - np.array([_flux(c, origin + size * a, a) for c in slabs])) / size
    h = heights - centre
    below = np.cumsum(w)[:-1] - h * np.cumsum(m)[:-1]
    w_above, m_above = np.cumsum(w[::-1])[::-1][1:], np.cumsum(m[::-1])[::-1][1:]
    above = volume - (w_above - h * m_above)
    return (below + above) / 2, float(w.sum() - volume), len(pieces)


#: cuts of a sweep after which their pace may stop a run that would go past its budget
PACE_CUTS = 3


def sweep(shape, direction, origin, volume: float, size: float, *, levels=None, tolerances=None,
          pieces: int = 2, deadline: float = math.inf, later: int = 0) -> Sweep:
    """``∫h dV`` and ``∫h² dV`` of ``shape`` along the unit ``direction``, ``h`` the height
    above the point ``origin`` (the part's centre), from ``V(t)`` at the Gauss–Kronrod nodes between the critical
    ``levels`` (found when not given, with the ``tolerances`` of the sub-shapes there:
    nodes keep clear of each level by twice its tolerance); ``volume`` is the solid's
    trusted volume, ``size`` at least the part's half diagonal (the planes' half side).  The
    sweep stops with ``SurfmodError`` naming ``budget`` past ``deadline`` (a
    ``time.perf_counter`` value), or as soon as the pace of its cuts so far says that this
    sweep and the ``later`` intervals of the sweeps after it would end past it (the cost of
    a cut varies far more between solids than any count of planes and faces foresees: the
    splitter's retries, sections it walks)."""
    a = np.asarray(direction, dtype=float)
    if levels is None:
        levels, tolerances = _Levels(shape).along(a, tolerances=True)
    levels = np.asarray(levels, dtype=float)
    extent = levels[-1] - levels[0]
    if not extent > 0:
        raise SurfmodError("shape: has no extent along the sweep direction")
    ends, mapped = _intervals(levels, 1e-6 * extent, pieces, tolerances)
    t, scale = _nodes(ends, mapped)
    origin = np.asarray(origin, dtype=float)
    centre = float(a @ origin)
    # one cut per interval: a piece the splitter loses (it happens, rarely, among a hundred
    # planes) shows as that interval's defect, and the cut is tried again another way
    vt = np.empty_like(t)
    defects = np.empty(len(t))
    n_pieces = 0
    began = time.perf_counter()
    for k, nodes in enumerate(t):
        now = time.perf_counter()
        # the pace of three cuts or more (one may have been a slow retry)
        ends_at = now + (now - began) / k * (len(t) - k + later) if k >= PACE_CUTS else now
        if ends_at > deadline:
            raise SurfmodError(f"budget: the moment reference would end about {ends_at - deadline:.0f} s past its "
                               f"budget on this solid, at the pace of its cuts ({len(t)} intervals along "
                               f"{np.round(a, 3).tolist()}, {k} cut, {later} more in the sweeps after it)")
        vt[k], defects[k], n = _cut_interval(shape, a, nodes, volume, origin, size)
        n_pieces += n
    h = t - centre
    h1 = ends[-1] - centre
    q0 = float(((scale * vt) @ KRONROD_W).sum())
    q1 = float(((scale * h * vt) @ KRONROD_W).sum())
    first = h1 * volume - q0
    second = h1 * h1 * volume - 2 * q1
    # an interval's defect is a volume its cut lost or gained: it moves V(t) there by at
    # most that much, so ∫V dt by |defect| times the length and ∫hV dt by that times |h|
    lengths = np.diff(ends)
    reach = np.maximum(np.abs(ends[:-1] - centre), np.abs(ends[1:] - centre))
    e0 = float(_quad_error(vt, scale).sum() + (np.abs(defects) * lengths).sum())
    e1 = 2 * float(_quad_error(h * vt, scale).sum() + (np.abs(defects) * lengths * reach).sum())
    worst = float(defects[np.argmax(np.abs(defects))]) if len(defects) else 0.0
    return Sweep(a, float(centre), first, second, e0, e1, ends, int(t.size), worst, n_pieces)


#: a cut whose slabs miss the volume by more than this (relative) is tried again
RETRY_DEFECT = 1e-10


def _cut_interval(shape, a, nodes, volume, origin, size):
    """``V`` at one interval's nodes: one split, then (if its defect is large) the split
    with axis-aligned boxes instead of oriented ones, then the odd and even nodes apart;
    the attempt with the smallest defect is kept."""
    best = cut_volumes(shape, a, nodes, volume, origin, size)
    if abs(best[1]) <= RETRY_DEFECT * volume:
        return best
    other = cut_volumes(shape, a, nodes, volume, origin, size, obb=False)
    best = min(best, other, key=lambda r: abs(r[1]))
    if abs(best[1]) <= RETRY_DEFECT * volume:
        return best
    halves = [cut_volumes(shape, a, nodes[i::2], volume, origin, size) for i in (0, 1)]
    vt = np.empty_like(nodes)
    vt[0::2], vt[1::2] = halves[0][0], halves[1][0]
    split = vt, max((h[1] for h in halves), key=abs), halves[0][2] + halves[1][2]
    return min(best, split, key=lambda r: abs(r[1]))


def _interval_count(levels, tolerances, pieces: int) -> int:
    """How many intervals :func:`sweep` cuts along levels ``levels`` (0 where it refuses)."""
    try:
        return len(_intervals(levels, 1e-6 * (levels[-1] - levels[0]), pieces, tolerances)[1])
    except SurfmodError:
        return 0


def moment_reference(shape, volume: float | None = None, *, pieces: int = 2,
                     budget: float | None = None) -> MomentReference:
    """Volume, centroid and inertia (about the centroid, ``Ixy = -∫xy``) of a solid from
    six volume sweeps (see the module notes), with error estimates.  ``volume`` is the
    trusted volume (BRepGProp's at eps 1e-12 when not given); ``pieces`` the fewest
    intervals along each direction (longer ones are split).  Nodes keep clear of each
    critical level by twice the tolerance of the sub-shapes there.  ``budget`` bounds the seconds spent
    (checked between cuts, against the pace of the cuts so far: ``SurfmodError`` naming
    ``budget`` as soon as the run would exceed it).

    >>> import build123d as bd
    >>> r = moment_reference(bd.Box(2, 3, 4).translate((1, 0, 0)).wrapped)
    >>> [round(float(x), 12) for x in r.centroid], round(float(r.inertia[0, 0]), 10)
    ([1.0, 0.0, 0.0], 50.0)
    """
    start = time.perf_counter()
    deadline = math.inf if budget is None else start + float(budget)
    solids = solids_of(shape)
    if not solids:
        raise SurfmodError("shape: has no solid to weigh")
    if volume is None:
        props = GProp_GProps()
        with kernel("BRepGProp.VolumeProperties_s"):
            BRepGProp.VolumeProperties_s(shape, props, 1e-12, False, False)
        volume = props.Mass()
    volume = float(volume)
    finder = _Levels(shape)
    levels = [finder.along(d, tolerances=True) for d in DIRECTIONS]
    # heights from the centre of the axes' extents (no cancellation against far origins)
    centre = np.array([(lv[0] + lv[-1]) / 2 for lv, _ in levels[:3]])
    size = 0.6 * float(np.linalg.norm([lv[-1] - lv[0] for lv, _ in levels[:3]])) + 10 * max_tolerance(shape)
    counts = [_interval_count(lv, tl, pieces) for lv, tl in levels]
    sweeps = [sweep(shape, d, centre, volume, size, levels=lv, tolerances=tl, pieces=pieces, deadline=deadline,
                    later=sum(counts[i + 1:]))
              for i, (d, (lv, tl)) in enumerate(zip(DIRECTIONS, levels))]
    s1 = np.array([s.first for s in sweeps[:3]])
    e1 = np.array([s.first_error for s in sweeps[:3]])
    second = np.diag([s.second for s in sweeps[:3]])
    e2 = np.diag([s.second_error for s in sweeps[:3]])
    for (i, j), s in zip(_PAIRS, sweeps[3:]):
        second[i, j] = second[j, i] = s.second - (second[i, i] + second[j, j]) / 2
        e2[i, j] = e2[j, i] = s.second_error + (e2[i, i] + e2[j, j]) / 2
    g = s1 / volume
    central = second - volume * np.outer(g, g)
    inertia = np.trace(central) * np.eye(3) - central
    ec = e2 + volume * (np.abs(np.outer(g, e1 / volume)) + np.abs(np.outer(e1 / volume, g)))
    inertia_error = float(2 * np.trace(ec) + ec.max())
    length = volume ** (1 / 3)
    check = max(abs(s.first - (s1[i] + s1[j]) / math.sqrt(2)) for (i, j), s in zip(_PAIRS, sweeps[3:]))
    return MomentReference(
        volume, centre + g, inertia, float(e1.max() / volume), inertia_error,
        max(abs(s.defect) for s in sweeps) / volume, check / (volume * length),
        sum(s.planes for s in sweeps), time.perf_counter() - start, tuple(sweeps))
