"""Catmull–Clark limit surfaces as CAD patches (``sm.limit_surface``): exact bicubic
B-spline patches on regular faces, Loop & Schaefer's approximate Bézier patches at
extraordinary vertices with the exact limit normal there, refined ``adaptive`` times.

The patches are watertight everywhere; the gaps, normal angles and distances to the exact
limit are measured on construction (:attr:`LimitSurface.errors`).
See :doc:`/guide/surfaces` (section "Subdivision and its limit surface").
"""

from __future__ import annotations

import numpy as np

from .. import checks
from ..errors import SurfmodError
from ..meshing.polymesh import Mesh
from ..nets.bezier import BezierSurface
from ..nets.bspline import BSplineSurface
from . import topology as tp
from .catmull_clark import step as cc_step
from .masks import cc_limit

#: Most patches a limit surface may have (each becomes an OCCT face).
MAX_PATCHES = 200_000
#: Most faces of the finest mesh built to place and measure the patches.
MAX_MEASURED_FACES = 4_000_000

# uniform cubic B-spline segment -> Bézier control points (one direction)
_BSPLINE_TO_BEZIER = np.array([[1, 4, 1, 0], [0, 4, 2, 0], [0, 2, 4, 0], [0, 1, 4, 1]], dtype=float) / 6.0
# parameter corners of a quad face, corner k
_CORNER_UV = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def _rot(ij, k):
    i, j = ij
    for _ in range(k):
        i, j = 3 - j, i
    return i, j


def _bernstein(t):
    """Cubic Bernstein values and first derivatives, ``(N, 4)`` each."""
    s = 1.0 - t
    b = np.stack([s**3, 3 * t * s**2, 3 * t**2 * s, t**3], axis=1)
    d = np.stack([-3 * s**2, 3 * s**2 - 6 * t * s, 6 * t * s - 3 * t**2, 3 * t**2], axis=1)
    return b, d


def bezier_eval(nets, u, v):
    """Positions and unit normals of bicubic Bézier nets ``(N, 4, 4, 3)`` at ``(u, v)``."""
    bu, du = _bernstein(np.asarray(u, float))
    bv, dv = _bernstein(np.asarray(v, float))
    p = np.einsum("ni,nj,nijk->nk", bu, bv, nets)
    su = np.einsum("ni,nj,nijk->nk", du, bv, nets)
    sv = np.einsum("ni,nj,nijk->nk", bu, dv, nets)
    n = np.cross(su, sv)
    with np.errstate(invalid="ignore", divide="ignore"):  # NaN where Su x Sv vanishes
        return p, n / np.linalg.norm(n, axis=1, keepdims=True)


def _nanmax(a) -> float:
    """Largest non-NaN value (NaN when there is none), without NumPy's warning."""
    a = np.asarray(a, dtype=float)
    ok = ~np.isnan(a)
    return float(a[ok].max()) if ok.any() else float("nan")


def _angle_deg(n1, n2):
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(n1, n2), axis=1), np.einsum("ij,ij->i", n1, n2)))


class LimitSurface:
    """The Catmull–Clark limit of a quad/polygon cage as surfmod patches.

    Attributes: ``patches`` (list of surfmod surfaces, one per face of ``mesh``),
    ``regular`` (bool array: exact uniform cubic B-spline patch), ``mesh`` (the
    subdivided control mesh), ``bezier_nets`` ``(P, 4, 4, 3)`` (every patch in Bézier
    form), ``levels`` and ``errors`` (measured figures, see :func:`limit_surface`).
    ``shape()`` is the sewn solid (closed cage) or shell (open cage); ``wrapped`` is its
    ``TopoDS_Shape``, so ``sm.export_step(limit, path)`` works directly.

    >>> import surfmod as sm
    >>> cube_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    >>> cube_f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> lim = sm.limit_surface(cube_v, cube_f)
    >>> len(lim.patches), int(lim.regular.sum()), lim.errors["max_gap"] < 1e-12
    (96, 72, True)
    """

    def __init__(self, mesh, patches, regular, bezier_nets, levels, errors, adaptive=0):
        self.adaptive = adaptive
        self.mesh = mesh
        self.patches = list(patches)
        self.regular = regular
        self.bezier_nets = bezier_nets
        self.levels = levels
        self.errors = errors

    def __repr__(self):
        e = self.errors
        return (
            f"LimitSurface({len(self.patches)} patches, {int(self.regular.sum())} exact B-spline, "
            f"max gap {e['max_gap']:.2g}, max normal jump {e['max_normal_angle_deg']:.3g} deg)"
        )

    @property
    def open(self) -> bool:
        """True when the cage has boundary edges (the limit is a shell, not a solid)."""
        return bool(self.errors.get("boundary_edges", 0))

    def faces(self):
        """One build123d ``Face`` per patch."""
        return [p.face() for p in self.patches]

    def _tolerance(self):
        size = float(np.ptp(self.mesh.vertices, axis=0).max())
        return max(1e-7 * size, 1e-9, 10 * self.errors["max_gap"])

    def shell(self):
        """The patches sewn (``BRepBuilderAPI_Sewing``) into one build123d ``Shell``."""
        from ..occ.subdiv import shell

        return shell(self.faces(), self._tolerance())[0]

    def solid(self):
        """The closed, outward-oriented build123d ``Solid`` bounded by the patches (closed
        cages only; an open cage gives a :meth:`shell`)."""
        from ..occ.subdiv import solid

        if self.open:
            raise SurfmodError("solid: the cage has boundary edges, so its limit bounds no solid; use shell()")
        return solid(self.faces(), self._tolerance())[0]

    def occt_continuity(self, samples: int = 17) -> dict:
        """The gap and normal jump across shared edges measured by OCCT on the sewn
        :meth:`shape` (through each face's p-curve): an independent check of ``errors``.

        Crease edges are included in the angle here, so compare on crease-free cages.
        """
        from ..occ.subdiv import shared_edge_samples

        samples = checks.count(samples, "samples", minimum=2)
        edges = shared_edge_samples(self.shape(), samples)
        gap, angle = 0.0, 0.0
        for (p0, p1), (n0, n1) in edges:
            gap = max(gap, float(np.linalg.norm(p0 - p1, axis=1).max()))
            ok = np.linalg.norm(n0, axis=1) * np.linalg.norm(n1, axis=1) > 0
            if ok.any():
                angle = max(angle, float(_angle_deg(n0[ok], n1[ok]).max()))
        return {"max_gap": gap, "max_normal_angle_deg": angle, "shared_edges": len(edges)}

    def shape(self):
        """:meth:`solid` for a closed cage, :meth:`shell` for an open one (built once)."""
        if getattr(self, "_shape", None) is None:
            self._shape = self.shell() if self.open else self.solid()
        return self._shape

    @property
    def wrapped(self):
        """The OCCT ``TopoDS_Shape`` of :meth:`shape` (build123d's convention)."""
        return self.shape().wrapped


def limit_surface(
    vertices, quads, *, levels: int = 2, adaptive: int = 0, creases=None, tangent_plane: bool = True
) -> LimitSurface:
    """The Catmull–Clark limit surface of a consistently oriented cage as CAD patches.

    ``quads`` may hold any polygons when ``levels >= 1`` (one step makes them quads);
    ``creases`` are sharp cage edges as in :func:`catmull_clark` (patches meet there with
    a crease, C0, and a straight crease through regular vertices keeps exact patches).
    Regular faces give exact bicubic uniform B-spline patches; faces at extraordinary
    vertices give approximating bicubic Bézier patches (:doc:`/guide/surfaces` (section
    "Subdivision and its limit surface")).
    ``adaptive`` more levels refine only the faces at extraordinary vertices (feature
    adaptive, like OpenSubdiv): each one splits into three exact patches and one smaller
    approximate patch, so the approximation error shrinks about twofold per level while
    the patch count grows only linearly (patches of different levels meet in T-junctions,
    which the sewing splits).

    ``errors`` holds the measured figures: ``max_gap`` and ``max_normal_angle_deg`` across
    edges between patches (crease edges excluded from the angle; ``..._regular_deg``
    between exact patches; ``degenerate_normals`` counts samples where ``Su x Sv``
    vanishes, e.g. where a smooth boundary curve turns through a single face),
    ``max_limit_deviation`` and ``max_limit_normal_deg`` against the exact limit at the
    vertices of further subdivision levels placed with the limit masks (``..._rel``
    relative to the cage size, ``..._regular`` on exact patches only),
    ``acc_regular_mismatch`` (the Bézier rules against the exact conversion on regular
    faces) and ``boundary_edges``.

    >>> import surfmod as sm
    >>> cube_v = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    >>> cube_f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    >>> solid = sm.limit_surface(cube_v, cube_f).solid()
    >>> len(solid.faces()), round(solid.volume, 3)
    (96, 0.328)
    >>> fine = sm.limit_surface(cube_v, cube_f, adaptive=3)
    >>> len(fine.patches), fine.errors["max_normal_angle_deg"] < 0.2
    (312, True)
    """
    v, topo = tp.polygon_mesh(vertices, quads, faces_name="quads")
    if not np.ptp(v, axis=0).max() > 0:
        raise SurfmodError("vertices: all cage vertices coincide, the limit surface is a point")
    n = tp.levels_arg(levels, len(topo.corners))
    if len(topo.corners) * 4.0 ** max(n - 1, 0) > MAX_PATCHES:
        raise SurfmodError(f"levels: {n} levels would make more than {MAX_PATCHES:,} patches")
    a = checks.count(adaptive, "adaptive", minimum=0)
    extra = 2  # measuring levels beyond the finest (samples on a 5 x 5 grid per finest face)
    if np.log(len(topo.corners)) + (max(n - 1, 0) + a + extra) * np.log(4.0) > np.log(MAX_MEASURED_FACES):
        raise SurfmodError(
            f"adaptive: levels={n} plus adaptive={a} refine too deep to build and measure "
            f"(more than {MAX_MEASURED_FACES:,} faces); use fewer levels"
        )
    if not isinstance(tangent_plane, (bool, np.bool_)):
        raise SurfmodError(f"tangent_plane: expected True or False, got {tangent_plane!r}")
    if n == 0 and np.any(topo.sizes != 4):
        raise SurfmodError("quads: with levels=0 every face must be a quad (use levels >= 1)")
    tp.require_oriented(topo, "quads")
    crease = tp.crease_flags(topo, creases)
    for _ in range(n):
        v, topo, crease = cc_step(v, topo, crease)
    return _assemble(v, topo, crease, n, a, bool(tangent_plane), extra)


def _assemble(v, topo, crease, levels, adaptive, tangent_plane, extra):
    """Patches of every adaptive level, the kept selection, and the measurements."""
    mesh = Mesh(v, topo.quads(), {"levels": levels, "scheme": "catmull-clark"})
    boundary_edges = int(topo.boundary.sum())
    active = np.ones(topo.n_faces, dtype=bool)
    owner = np.full(topo.n_faces, -1)
    maps = _identity_maps(topo.n_faces)
    patches, regular, nets, mismatch = [], [], [], 0.0
    for j in range(adaptive + 1):
        reg_j, nets_j, bnets_j, mism = _level_patches(v, topo, crease, tangent_plane)
        keep = active if j == adaptive else active & reg_j
        mismatch = max(mismatch, mism)
        kept = np.flatnonzero(keep)
        bpos = np.cumsum(reg_j) - 1  # row of each regular face in bnets_j
        first = len(patches)
        for f in kept:
            if reg_j[f]:
                patches.append(BSplineSurface.uniform_cubic(bnets_j[bpos[f]]))
            else:
                patches.append(BezierSurface._trusted(nets_j[f]))
        regular.append(reg_j[kept])
        nets.append(nets_j[kept])
        # newly owned faces parametrize their patch directly
        owner[kept] = first + np.arange(len(kept))
        for m, identity in zip(maps, _identity_maps(len(kept))):
            m[kept] = identity
        if j < adaptive:
            active = np.repeat(active & ~reg_j, 4)
            v, topo, crease, owner, maps = _refine(v, topo, crease, owner, maps)
    regular = np.concatenate(regular)
    nets = np.concatenate(nets)
    nets.setflags(write=False)
    errors = _measure(v, topo, crease, owner, maps, nets, regular, extra)
    errors["acc_regular_mismatch"] = mismatch
    errors["boundary_edges"] = boundary_edges
    regular = np.array(regular, dtype=bool)
    regular.setflags(write=False)
    return LimitSurface(mesh, patches, regular, nets, levels, errors, adaptive)


def _identity_maps(n):
    """Affine maps (origin, d1, d2) from a face's own (s, t) to its patch's (u, v)."""
    return [np.zeros((n, 2)), np.tile([1.0, 0.0], (n, 1)), np.tile([0.0, 1.0], (n, 1))]


def _refine(v, topo, crease, owner, maps):
    """One Catmull–Clark step carrying each face's patch owner and (s, t) -> (u, v) map.

    Child ``j`` of a quad is ``[c_j, e_j, f, e_(j-1)]``: its local axes run from corner j
    halfway towards corners j+1 and j-1 of the parent."""
    nf = topo.n_faces
    v, topo, crease = cc_step(v, topo, crease)
    j = np.tile(np.arange(4), nf)
    par = np.repeat(np.arange(nf), 4)
    origin, d1, d2 = maps
    pj, pn, pp = _CORNER_UV[j], _CORNER_UV[(j + 1) % 4], _CORNER_UV[(j - 1) % 4]

    def amap(x):
        return d1[par] * x[:, :1] + d2[par] * x[:, 1:]

    maps = [origin[par] + amap(pj), 0.5 * amap(pn - pj), 0.5 * amap(pp - pj)]
    return v, topo, crease, owner[par], maps


def _regular_corners(topo, twin, nsharp):
    """Per corner: is the limit there a B-spline (possibly continued by ghost points)?

    A smooth vertex must have valence 4; a vertex on sharp (boundary/crease) edges must
    have, in the sector of faces between its sharp edges that holds the corner, two faces
    and exactly two sharp edges (the curve rule) or one face and be a corner."""
    corners, nxt, prv = topo.corners, topo.nxt, topo.prv

    def step(arr, idx):
        ok = idx >= 0
        return np.where(ok, arr[np.maximum(idx, 0)], -1)

    fwd = twin[prv]  # corner at the same vertex in the face across the previous edge
    bwd = step(nxt, twin)  # ... across the next edge
    one = (fwd < 0) & (bwd < 0)
    two = ((fwd >= 0) & (bwd < 0) & (step(fwd, fwd) < 0)) | ((bwd >= 0) & (fwd < 0) & (step(bwd, bwd) < 0))
    ns = nsharp[corners]
    sectors = (one & (ns >= 3)) | (two & (ns == 2))
    return np.where(ns > 0, sectors, topo.valence()[corners] == 4)


def _level_patches(v, topo, crease, tangent_plane):
    """Regular flags, Bézier nets ``(F, 4, 4, 3)`` (exact on regular faces), 4x4 B-spline
    nets of the regular faces and the ACC-vs-exact mismatch, for one level."""
    corners, nxt, prv = topo.corners, topo.nxt, topo.prv
    full_twin = topo.twin()
    sharp = crease | topo.boundary
    twin = np.where(sharp[topo.edge_of], -1, full_twin)  # patches are cut along sharp edges
    nf = topo.n_faces
    valence = topo.valence()
    nsharp = np.bincount(topo.edges[sharp].ravel(), minlength=len(v))
    nsharp[topo.faces_at() == 1] = 3  # a boundary vertex of a single face is a corner
    on_curve = nsharp >= 2  # boundary/crease curve vertices and corners
    regular = np.all(_regular_corners(topo, twin, nsharp).reshape(-1, 4), axis=1)
    limit_pos, normals, _ = cc_limit(v, topo, crease)

    # ACC rules (curve vertices weighted as regular ones continued by ghost points)
    nval = np.where(on_curve, 4, valence)[corners].astype(float)[:, None]
    interior = (
        nval * v[corners] + 2.0 * (v[corners[nxt]] + v[corners[prv]]) + v[corners[nxt[nxt]]]
    ) / (nval + 5.0)
    csum = np.zeros_like(v)
    np.add.at(csum, corners, interior)
    corner_pts = csum / topo.faces_at()[:, None]
    corner_pts[on_curve] = limit_pos[on_curve]  # on the cubic B-spline boundary/crease curve
    inner = twin >= 0
    tw = np.where(inner, twin, 0)
    a, b = v[corners], v[corners[nxt]]
    near_start = np.where(inner[:, None], 0.5 * (interior + interior[nxt[tw]]), (2.0 * a + b) / 3.0)
    near_end = np.where(inner[:, None], 0.5 * (interior[nxt] + interior[tw]), (a + 2.0 * b) / 3.0)
    if tangent_plane:
        for pts, vert in ((near_start, corners), (near_end, corners[nxt])):
            ev = (valence[vert] != 4) & (nsharp[vert] == 0) & np.isfinite(normals[vert, 0])
            nn = normals[vert[ev]]
            d = np.einsum("ij,ij->i", pts[ev] - corner_pts[vert[ev]], nn)
            pts[ev] -= d[:, None] * nn

    nets = np.empty((nf, 4, 4, 3))
    c4 = np.arange(nf) * 4
    for k in range(4):
        c = c4 + k
        nets[:, [0, 3, 3, 0][k], [0, 0, 3, 3][k]] = corner_pts[corners[c]]
        nets[:, [1, 2, 2, 1][k], [1, 1, 2, 2][k]] = interior[c]
        # edge k runs corner k -> corner k+1
        (i0, j0), (i1, j1) = [((1, 0), (2, 0)), ((3, 1), (3, 2)), ((2, 3), (1, 3)), ((0, 2), (0, 1))][k]
        nets[:, i0, j0] = near_start[c]
        nets[:, i1, j1] = near_end[c]

    # exact 4x4 B-spline nets of the regular faces (ghost rows 2 b - i beyond a boundary)
    rf = np.flatnonzero(regular)
    bnets = np.full((len(rf), 4, 4, 3), np.nan)
    for k in range(4):
        c = 4 * rf + k
        bnets[(slice(None), *_rot((1, 1), k))] = v[corners[c]]
        has = np.flatnonzero(twin[c] >= 0)
        g = twin[c[has]]
        bnets[(has, *_rot((1, 0), k))] = v[corners[nxt[nxt[g]]]]
        bnets[(has, *_rot((2, 0), k))] = v[corners[prv[g]]]
        h = twin[nxt[g]]
        hh = h >= 0
        bnets[(has[hh], *_rot((0, 0), k))] = v[corners[prv[h[hh]]]]
    for ii in ((1, 2), (0, 3)):  # corners of a ghost row last: they may need a ghost column
        for k in range(4):
            ghost = np.flatnonzero(twin[4 * rf + k] < 0)
            for i in ii:
                out, near, far = _rot((i, 0), k), _rot((i, 1), k), _rot((i, 2), k)
                bnets[(ghost, *out)] = 2.0 * bnets[(ghost, *near)] - bnets[(ghost, *far)]
    exact = np.einsum("ai,nijk,bj->nabk", _BSPLINE_TO_BEZIER, bnets, _BSPLINE_TO_BEZIER)
    # the ACC rules must reproduce the exact Bézier points on regular faces (watertightness)
    acc_mismatch = float(np.abs(nets[rf] - exact).max()) if len(rf) else 0.0
    nets[rf] = exact

    if not (np.all(np.isfinite(nets)) and np.all(np.isfinite(bnets))):
        raise SurfmodError("vertices: degenerate cage, the limit patches are undefined (coincident points?)")
    return regular, nets, bnets, acc_mismatch


def _bezier_at(nets, idx, u, v, chunk: int = 1 << 16):
    """:func:`bezier_eval` of ``nets[idx]`` in chunks (bounded memory)."""
    out_p, out_n = np.empty((len(idx), 3)), np.empty((len(idx), 3))
    for s in range(0, len(idx), chunk):
        sl = slice(s, s + chunk)
        out_p[sl], out_n[sl] = bezier_eval(nets[idx[sl]], u[sl], v[sl])
    return out_p, out_n


def _apply(maps, faces, st):
    origin, d1, d2 = maps
    return origin[faces] + d1[faces] * st[:, :1] + d2[faces] * st[:, 1:]


def _measure(v, topo, crease, owner, maps, nets, regular, extra, samples: int = 17):
    """Measured continuity and approximation figures (see :func:`limit_surface`), on the
    finest mesh whose faces know their patch (``owner``) and place in it (``maps``)."""
    size = float(np.ptp(v, axis=0).max()) or 1.0
    # 1. across every edge between two different patches: gap and normal angle
    twin = topo.twin()
    c = np.flatnonzero(np.arange(len(twin)) < twin)
    c = c[owner[c // 4] != owner[twin[c] // 4]]
    g = twin[c]
    t = np.linspace(0.0, 1.0, samples)
    k, l = np.repeat(c % 4, samples), np.repeat(g % 4, samples)
    tt = np.tile(t, len(c))[:, None]
    st_f = _CORNER_UV[k] * (1 - tt) + _CORNER_UV[(k + 1) % 4] * tt
    st_g = _CORNER_UV[l] * tt + _CORNER_UV[(l + 1) % 4] * (1 - tt)
    ff, fg = np.repeat(c // 4, samples), np.repeat(g // 4, samples)
    uv_f, uv_g = _apply(maps, ff, st_f), _apply(maps, fg, st_g)
    pf, nf_ = _bezier_at(nets, owner[ff], uv_f[:, 0], uv_f[:, 1])
    pg, ng = _bezier_at(nets, owner[fg], uv_g[:, 0], uv_g[:, 1])
    gap = float(np.linalg.norm(pf - pg, axis=1).max()) if len(c) else 0.0
    smooth = np.repeat(~crease[topo.edge_of[c]], samples)  # creases are meant to be sharp
    jump = _angle_deg(nf_, ng)[smooth]
    degenerate = int(np.isnan(jump).sum())
    edge_reg = (regular[owner[ff]] & regular[owner[fg]])[smooth]

    # 2. against the exact limit: vertices of further levels, placed with the masks
    fine_v, fine_topo, fine_crease, fine_owner, fine_maps = v, topo, crease, owner, maps
    for _ in range(extra):
        fine_v, fine_topo, fine_crease, fine_owner, fine_maps = _refine(fine_v, fine_topo, fine_crease, fine_owner, fine_maps)
    pos, nrm, _ = cc_limit(fine_v, fine_topo, fine_crease)
    faces = np.repeat(np.arange(fine_topo.n_faces), 4)
    corner = np.tile(np.arange(4), fine_topo.n_faces)
    vert = fine_topo.corners
    # one sample per (vertex, patch): vertices on patch borders are checked on each side
    _, first = np.unique(vert * len(nets) + fine_owner[faces], return_index=True)
    faces, corner, vert = faces[first], corner[first], vert[first]
    uv = _apply(fine_maps, faces, _CORNER_UV[corner])
    p, nn = _bezier_at(nets, fine_owner[faces], uv[:, 0], uv[:, 1])
    dev = np.linalg.norm(p - pos[vert], axis=1)
    ang = _angle_deg(nn, nrm[vert])
    reg = regular[fine_owner[faces]]
    return {
        "max_gap": gap,
        "max_gap_rel": gap / size,
        "max_normal_angle_deg": _nanmax(jump) if jump.size else 0.0,
        "max_normal_angle_regular_deg": _nanmax(jump[edge_reg]) if edge_reg.any() else 0.0,
        "degenerate_normals": degenerate,
        "max_limit_deviation": float(dev.max()),
        "max_limit_deviation_rel": float(dev.max()) / size,
        "max_limit_deviation_regular": float(dev[reg].max()) if reg.any() else 0.0,
        "max_limit_normal_deg": _nanmax(ang),
        "samples_per_edge": samples,
        "limit_samples": int(len(dev)),
        "patches": int(len(nets)),
        "regular_patches": int(regular.sum()),
    }
