"""Surface analysis without a GUI: zebra stripes, isophotes, curvature maps, curvature
combs and a fairness figure, as arrays and (optionally) a PNG.

Normals and curvatures come from surfmod's exact evaluator at the nodes of parameter-space
triangles, never from the triangles.  The same concept as :mod:`surfmod.cli.analyze` (the
``surfmod analyze`` command over this).  See :doc:`/guide/analysis`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..sides import normal_curvature
from ..readback import from_face
from ..surface import Surface
from .analyze_plot import write_analysis_png
from .grid import grid_faces
from .refine import edge_table

KINDS = ("zebra", "isophote", "gaussian", "mean", "max_abs", "comb")
#: Triangles shared out among the faces of a shape (keeps a whole part to a few seconds).
TRIANGLE_BUDGET = 60000


@dataclass(frozen=True)
class Fairness:
    """``area``, ``bending = int (k1^2 + k2^2) dA`` and ``variation = int |grad H|^2 dA``."""

    area: float
    bending: float
    variation: float


@dataclass(frozen=True)
class Patch:
    """One sampled surface: parameters ``uv`` ``(N, 2)``, ``points``/``normals`` ``(N, 3)``,
    ``triangles`` ``(T, 3)``, the analysed ``values`` ``(N,)`` and its ``fairness``;
    ``outside_only`` is True for faces of a solid (their insides are never seen)."""

    surface: Surface
    uv: np.ndarray
    points: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray
    values: np.ndarray
    fairness: Fairness
    outside_only: bool = False


@dataclass(frozen=True)
class Comb:
    """A curvature comb: base ``points`` ``(M, 3)``, normal ``curvature`` ``(M,)`` along the
    curve and the spike ``tips`` ``(M, 3)``; ``where`` says which curve it is."""

    where: str
    points: np.ndarray
    curvature: np.ndarray
    tips: np.ndarray


@dataclass(frozen=True)
class Analysis:
    """Result of :func:`analyze`: the ``kind``, the ``light`` direction, one
    :class:`Patch` per surface or face, the :class:`Comb` list (kind ``comb``) and the
    ``path`` of the PNG when one was written."""

    kind: str
    light: np.ndarray
    patches: tuple
    combs: tuple = field(default=())
    path: object = None

    @property
    def values(self) -> np.ndarray:
        return np.concatenate([p.values for p in self.patches]) if self.patches else np.empty(0)

    @property
    def normals(self) -> np.ndarray:
        return np.concatenate([p.normals for p in self.patches]) if self.patches else np.empty((0, 3))

    @property
    def fairness(self) -> tuple:
        return tuple(p.fairness for p in self.patches)

    def __str__(self) -> str:
        lines = [f"analysis {self.kind}: {len(self.patches)} patch(es)",
                 f"{'patch':>5} {'nodes':>7} {'min':>11} {'max':>11} {'area':>11} {'bending':>11} {'variation':>11}"]
        for i, p in enumerate(self.patches):
            f = p.fairness
            lo, hi = (float(p.values.min()), float(p.values.max())) if p.values.size else (np.nan, np.nan)
            lines.append(f"{i:>5} {len(p.uv):>7} {lo:>11.4g} {hi:>11.4g} {f.area:>11.4g} {f.bending:>11.4g} {f.variation:>11.4g}")
        return "\n".join(lines)


# -- sampling --------------------------------------------------------------------------------------
def _surface_samples(s: Surface, resolution: int):
    (u0, u1), (v0, v1) = s.domain
    us, vs = np.linspace(u0, u1, resolution), np.linspace(v0, v1, resolution)
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    return np.stack([uu.ravel(), vv.ravel()], 1), grid_faces(resolution, resolution), 1.0


def refine(uv: np.ndarray, tri: np.ndarray):
    """One uniform 4-split of a triangulation (shared edge midpoints, so it stays conforming)."""
    sides, unique, _ = edge_table(tri)
    mid = len(uv) + sides                                         # (T, 3) midpoints of e01, e12, e20
    uv = np.concatenate([uv, 0.5 * (uv[unique[:, 0]] + uv[unique[:, 1]])])
    a, b, c = tri.T
    m01, m12, m20 = mid.T
    tri = np.concatenate([np.stack(x, 1) for x in ((a, m01, m20), (m01, b, m12), (m20, m12, c), (m01, m12, m20))])
    return uv, tri


def _face_samples(face, target: float, max_triangles: int = 20000):
    """OCCT's triangulation of the trimmed region, split until 3-D edges are <= ``target``."""
    from ..occ.topo import face_surface
    from ..occ.mesh import face_uv_triangles

    s = from_face(face)
    _, _, reversed_ = face_surface(face)
    (u0, u1), (v0, v1) = s.domain
    uv, tri = face_uv_triangles(face, target, 0.1)
    uv = np.stack([np.clip(uv[:, 0], u0, u1), np.clip(uv[:, 1], v0, v1)], 1)
    while 4 * len(tri) <= max_triangles:
        p = s.points(uv[:, 0], uv[:, 1])[tri]
        longest = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=2).max()
        if longest <= target:
            break
        uv, tri = refine(uv, tri)
    return s, uv, tri, -1.0 if reversed_ else 1.0


def _items(obj, name: str):
    """``[(surface, uv, triangles, orientation sign, face or None)]`` for the object."""
    from ..occ.topo import faces_of, solids_of, wrapped

    if isinstance(obj, Surface):
        return [("surface", obj)]
    items = obj if isinstance(obj, (list, tuple)) else [obj]
    out = []
    for item in items:
        if isinstance(item, Surface):
            out.append(("surface", item))
            continue
        if wrapped(item) is None:
            raise SurfmodError(f"{name}: expected a surfmod surface, a face or a shape, got {type(item).__name__}")
        kind = "solid face" if solids_of(wrapped(item)) else "face"
        out.extend((kind, f) for f in faces_of(item))
    if not out:
        raise SurfmodError(f"{name}: has no faces to analyse")
    return out


def fairness(points, triangles, k1, k2, mean) -> Fairness:
    """Trapezoid-rule fairness integrals over a triangulated patch (see :doc:`/guide/analysis`)."""
    p = points[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    bend = (k1 * k1 + k2 * k2)[triangles].mean(axis=1)
    h = mean[triangles]
    g11, g12, g22 = (np.einsum("ij,ij->i", x, y) for x, y in ((e1, e1), (e1, e2), (e2, e2)))
    det = g11 * g22 - g12 * g12
    ok = det > 1e-300
    det = np.where(ok, det, 1.0)
    d1, d2 = h[:, 1] - h[:, 0], h[:, 2] - h[:, 0]
    a, b = (g22 * d1 - g12 * d2) / det, (g11 * d2 - g12 * d1) / det
    grad = a[:, None] * e1 + b[:, None] * e2
    var = np.where(ok, np.einsum("ij,ij->i", grad, grad), 0.0)
    return Fairness(float(area.sum()), float((area * bend).sum()), float((area * var).sum()))


def _values(kind, normals, curv, light, stripes):
    if kind == "isophote":
        return normals @ light
    if kind == "zebra":
        angle = np.arccos(np.clip(normals @ light, -1.0, 1.0))
        band = np.minimum(np.floor(angle * (2 * stripes) / np.pi), 2 * stripes - 1)  # pi closes the last band
        return (band.astype(int) % 2).astype(float)
    if kind == "gaussian":
        return curv.gaussian
    if kind == "mean":
        return curv.mean
    return np.maximum(np.abs(curv.k1), np.abs(curv.k2))  # max_abs and comb


def _patch(kind, s, uv, tri, sign, light, stripes):
    ders = s.derivatives(uv[:, 0], uv[:, 1], 2)
    pts = ders[:, 0, 0]
    normals = sign * s.normals(uv[:, 0], uv[:, 1])
    curv = s.curvatures(uv[:, 0], uv[:, 1])
    if sign < 0:  # curvatures are signed against the normal: follow the flip
        curv = type(curv)(curv.gaussian, -curv.mean, -curv.k2, -curv.k1)
    values = _values(kind, normals, curv, light, stripes)
    return Patch(s, uv, pts, normals, tri, values, fairness(pts, tri, curv.k1, curv.k2, curv.mean))


# -- combs -----------------------------------------------------------------------------------------
def _comb_along(s: Surface, u, v, du, dv, sign):
    ders = s.derivatives(u, v, 2)
    n = sign * s.normals(u, v)
    direction = ders[:, 1, 0] * du[:, None] + ders[:, 0, 1] * dv[:, None]
    return ders[:, 0, 0], normal_curvature(ders, n, direction), n


def _surface_curves(s: Surface, count: int, samples: int):
    (u0, u1), (v0, v1) = s.domain
    t = np.linspace(0.0, 1.0, samples)
    out = []
    for k, f in enumerate(np.linspace(0.0, 1.0, count)):
        u = np.full(samples, u0 + f * (u1 - u0))
        out.append((f"u={u[0]:.4g}" + (" (side)" if k in (0, count - 1) else ""), u, v0 + t * (v1 - v0), 0.0, 1.0))
        v = np.full(samples, v0 + f * (v1 - v0))
        out.append((f"v={v[0]:.4g}" + (" (side)" if k in (0, count - 1) else ""), u0 + t * (u1 - u0), v, 1.0, 0.0))
    return out


def _combs(patches_src, count: int, samples: int, scale):
    raw = []
    for s, face, sign in patches_src:
        if face is None:
            for where, u, v, du, dv in _surface_curves(s, count, samples):
                p, k, n = _comb_along(s, u, v, np.full_like(u, du), np.full_like(v, dv), sign)
                raw.append((where, p, k, n))
        else:
            from ..occ.local_analysis import face_edges_uv

            (a0, a1), (b0, b1) = s.domain
            for i, (uv, tangent) in enumerate(face_edges_uv(face, samples)):
                u, v = np.clip(uv[:, 0], a0, a1), np.clip(uv[:, 1], b0, b1)
                p, k, n = _comb_along(s, u, v, tangent[:, 0], tangent[:, 1], sign)
                raw.append((f"edge {i}", p, k, n))
    if not raw:
        return ()
    pts = np.concatenate([r[1] for r in raw])
    size = float(np.linalg.norm(np.ptp(pts, axis=0))) or 1.0
    kmax = max(float(np.abs(r[2]).max()) for r in raw)
    factor = float(scale) if scale is not None else (0.1 * size / kmax if kmax > 0 else 0.0)
    return tuple(Comb(w, p, k, p - factor * k[:, None] * n) for w, p, k, n in raw)


# -- the public call ------------------------------------------------------------------------------
def analyze(obj, kind: str, out=None, *, light=None, stripes: int = 8, resolution: int = 80,
            comb_curves: int = 5, comb_scale=None, view=(28.0, -58.0), title=None) -> Analysis:
    """Analyse a surface, a face, a list of them or a whole shape (every face).

    ``kind``: ``"zebra"``, ``"isophote"``, ``"gaussian"``, ``"mean"``, ``"max_abs"`` or
    ``"comb"`` (see :doc:`/guide/analysis`).  ``light``: light direction for zebra and
    isophotes (default: the viewing direction of ``view = (elevation, azimuth)`` in
    degrees); ``stripes``: black stripes of the zebra over the half turn of the normal;
    ``resolution``: grid nodes per direction for surfaces (faces are triangulated to a
    comparable density); ``comb_curves``: iso-curves per direction for combs.  With
    ``out`` a PNG is written headless (matplotlib Agg, local canvas) with a scale bar for
    curvature maps.  Returns an :class:`Analysis` with the arrays and fairness figures.

    >>> import surfmod as sm
    >>> r = sm.analyze(sm.sphere(2.0), "gaussian", resolution=20)
    >>> round(float(r.values.mean()), 8)         # 1/R^2 everywhere
    0.25
    >>> round(r.fairness[0].variation, 12)       # constant mean curvature
    0.0
    """
    if kind not in KINDS:
        raise SurfmodError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    stripes = checks.count(stripes, "stripes")
    resolution = checks.count(resolution, "resolution", minimum=3)
    comb_curves = checks.count(comb_curves, "comb_curves", minimum=2)
    try:
        elev, azim = (float(x) for x in view)
    except (TypeError, ValueError):
        raise SurfmodError(f"view: expected (elevation, azimuth) in degrees, got {view!r}") from None
    e, a = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    light_dir = eye if light is None else checks.direction(light, "light")
    patches, sources = [], []
    items = _items(obj, "obj")
    target = None
    if any(what != "surface" for what, _ in items):
        from ..occ.properties import bounding_box
        from ..occ.topo import compound

        box = bounding_box(compound([f for what, f in items if what != "surface"]))
        target = float(np.linalg.norm(box[1] - box[0])) / resolution
    for what, item in items:
        if what == "surface":
            uv, tri, sign = _surface_samples(item, resolution)
            s, face = item, None
        else:
            s, uv, tri, sign = _face_samples(item, target, max(512, TRIANGLE_BUDGET // len(items)))
            face = item
        patch = _patch(kind, s, uv, tri, sign, light_dir, stripes)
        if what == "solid face":
            patch = replace(patch, outside_only=True)
        patches.append(patch)
        sources.append((s, face, sign))
    combs = _combs(sources, comb_curves, max(24, resolution), comb_scale) if kind == "comb" else ()
    result = Analysis(kind, light_dir, tuple(patches), combs)
    if out is not None:
        result = replace(result, path=write_analysis_png(result, out, eye, title=title, stripes=stripes))
    return result
