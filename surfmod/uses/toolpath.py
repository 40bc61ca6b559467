"""NC tool paths for continuous-path machining: drop-cutter zig-zag rasters.

The cutter is dropped along -Z onto the exact surface at every cutter location (CL)
``(x, y)`` of a zig-zag raster; the CL point is the tool tip.  For a ball of radius
``r`` centred above ``(x, y)`` the tip height is the maximum over surface points
``p`` within horizontal distance ``d ≤ r`` of ``p_z + sqrt(r² − d²) − r``; for a flat
end mill it is the highest surface point under the disc.  The maximum is found on
the NumPy evaluator in three steps, all vectorized over the CL points:

1. a dense (u, v) sample of every face, a KD-tree on its (x, y) (``scipy.spatial``)
   and the pairs "CL point – sample within r" give a first maximum and its seed;
2. zoom: around each seed a small (u, v) grid is evaluated and the best point kept,
   three times with shrinking spans;
3. ball cutters: Newton's method on ``∇h(u, v) = 0`` with the surface's second
   derivatives (h = contact height) polishes the contact point to round-off.

The result is checked for gouging on an independent, denser sample of the exact
surface (``Toolpath.gouge`` is the deepest penetration found; ~1e-12 in practice).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import checks
from ..errors import SurfmodError
from .faces import Patch, patches, surface_patch


@dataclass(frozen=True)
class Tool:
    """An end mill: ``kind`` ``"ball"`` or ``"flat"``, ``radius`` > 0.

    >>> import surfmod as sm
    >>> t = sm.Tool("ball", 3.0)
    >>> round(t.stepover_for_scallop(0.01), 6)
    0.48949
    """

    kind: str
    radius: float

    def __post_init__(self):
        if self.kind not in ("ball", "flat"):
            raise SurfmodError(f"tool: kind must be 'ball' or 'flat', got {self.kind!r}")
        object.__setattr__(self, "radius", checks.positive(self.radius, "tool radius"))

    @property
    def diameter(self) -> float:
        return 2.0 * self.radius

    def stepover_for_scallop(self, scallop: float) -> float:
        """Stepover giving cusps of height ``scallop`` on flat ground (ball cutters):
        ``2 sqrt(2 r h − h²)``."""
        h = checks.positive(scallop, "scallop")
        if self.kind != "ball":
            raise SurfmodError("scallop: a flat end mill leaves no scallop on flat ground; give stepover instead")
        if h >= self.radius:
            raise SurfmodError(f"scallop: must be smaller than the tool radius {self.radius:g}, got {h:g}")
        return float(2.0 * np.sqrt(2.0 * self.radius * h - h * h))

    def scallop_for_stepover(self, stepover: float) -> float:
        """Cusp height on flat ground for a given stepover (0 for a flat end mill)."""
        if self.kind != "ball":
            return 0.0
        r = self.radius
        return float(r - np.sqrt(max(r * r - (stepover / 2.0) ** 2, 0.0)))


@dataclass(frozen=True)
class Toolpath:
    """A continuous zig-zag tool path.

    ``points`` ``(N, 3)``: CL points (tool tip) in machining order, one continuous
    polyline (passes joined by drop-cut links); ``contacts`` ``(N, 3)``: the
    cutter-contact points on the surface; ``pass_index`` ``(N,)``: raster pass of each
    point (-1 on links); ``gouge``: deepest penetration of the tool into an
    independent dense sample of the exact surface (≤ 0 means none found).

    >>> import surfmod as sm
    >>> flat = sm.plane((0, 0, 0), (10, 0, 0), (0, 10, 0))
    >>> tp = sm.toolpath(flat, sm.Tool("ball", 1.0), stepover=1.0)
    >>> float(tp.points[:, 2].min()), tp.gouge <= 0   # the ball's tip rides on z = 0
    (0.0, True)
    """

    points: np.ndarray = field(repr=False)
    contacts: np.ndarray = field(repr=False)
    pass_index: np.ndarray = field(repr=False)
    tool: Tool
    stepover: float
    step: float
    scallop: float
    direction: str
    gouge: float

    @property
    def n_passes(self) -> int:
        return int(self.pass_index.max()) + 1

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def to_gcode(self, **kw) -> str:
        """The G-code text (see :func:`surfmod.export_gcode`)."""
        from ..io.gcode import gcode_text

        return gcode_text(self, **kw)

    def __str__(self) -> str:
        return (
            f"toolpath: {self.tool.kind} end mill r={self.tool.radius:g}, {self.n_passes} passes along {self.direction}, "
            f"{len(self.points)} points, stepover {self.stepover:.6g} (scallop {self.scallop:.3g} on flat ground), "
            f"length {self.length:.6g}, max gouge {max(self.gouge, 0.0):.2e}"
        )


# -- surface model: patches with samples --------------------------------------------------
@dataclass
class _Model:
    patches: list
    inside: list  # per patch: None (whole box) or callable(u, v) -> bool mask
    up_only: bool


def _model(obj) -> _Model:
    from ..surface import Surface
    from .inputs import to_shape

    if isinstance(obj, Surface):
        return _Model([surface_patch(obj)], [None], False)
    if isinstance(obj, (list, tuple)) and obj and all(isinstance(o, Surface) for o in obj):
        return _Model([surface_patch(s, i) for i, s in enumerate(obj)], [None] * len(obj), False)
    shape = to_shape(obj, "obj")
    pats = patches(shape)
    inside = []
    for p in pats:
        inside.append(None if p.natural else _trim_mask(p))
    from ..occ.uses import solids_of

    return _Model(pats, inside, bool(solids_of(shape)))


def _trim_mask(patch: Patch):
    """Vectorized inside test for a trimmed face: OCCT's (u, v) triangulation of the
    face and matplotlib's trapezoid-map triangle finder."""
    from matplotlib.tri import Triangulation

    from ..occ.uses import face_uv_triangles

    u0, u1, v0, v1 = patch.bounds
    uv, tri = face_uv_triangles(patch.face, 1e-3 * max(1.0, u1 - u0, v1 - v0))
    finder = Triangulation(uv[:, 0], uv[:, 1], tri).get_trifinder()

    def inside(u, v):
        return finder(u, v) >= 0

    return inside


def _grid_counts(patch: Patch, spacing: float, cap: int) -> tuple[int, int]:
    u0, u1, v0, v1 = patch.bounds
    uu, vv = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9), indexing="ij")
    p = patch.evaluate(uu.ravel(), vv.ravel(), 0)[:, 0, 0].reshape(9, 9, 3)
    lu = np.linalg.norm(np.diff(p, axis=0), axis=2).sum(axis=0).max()
    lv = np.linalg.norm(np.diff(p, axis=1), axis=2).sum(axis=1).max()
    nu = int(np.clip(np.ceil(lu / spacing) + 1, 3, cap))
    nv = int(np.clip(np.ceil(lv / spacing) + 1, 3, cap))
    return nu, nv


def _samples(model: _Model, spacing: float, shift: float = 0.0, cap: int = 1500):
    """Dense samples: points (M, 3), patch id (M,), u (M,), v (M,), spacing in u and v per patch."""
    pts, pid, us, vs, du, dv = [], [], [], [], [], []
    for k, (p, inside) in enumerate(zip(model.patches, model.inside)):
        nu, nv = _grid_counts(p, spacing, cap)
        u0, u1, v0, v1 = p.bounds
        hu, hv = (u1 - u0) / (nu - 1), (v1 - v0) / (nv - 1)
        gu = np.clip(np.linspace(u0, u1, nu) + shift * hu, u0, u1)
        gv = np.clip(np.linspace(v0, v1, nv) + shift * hv, v0, v1)
        uu, vv = (a.ravel() for a in np.meshgrid(gu, gv, indexing="ij"))
        keep = np.ones(uu.size, bool) if inside is None else inside(uu, vv)
        uu, vv = uu[keep], vv[keep]
        if not uu.size:
            continue
        d = p.evaluate(uu, vv, 1)
        if model.up_only:
            nz = p.sign * np.cross(d[:, 1, 0], d[:, 0, 1])[:, 2]
            up = nz >= -1e-12 * np.abs(nz).max()
            d, uu, vv = d[up], uu[up], vv[up]
        pts.append(d[:, 0, 0])
        pid.append(np.full(len(uu), k))
        us.append(uu)
        vs.append(vv)
        du.append(hu)
        dv.append(hv)
    if not pts:
        raise SurfmodError("obj: no upward-facing surface to machine")
    return np.concatenate(pts), np.concatenate(pid), np.concatenate(us), np.concatenate(vs), np.array(du), np.array(dv)


def _heights(tool: Tool, cl: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Tip height for CL (x, y) rows against surface points p (same length); -inf outside r."""
    d2 = (p[..., 0] - cl[..., 0]) ** 2 + (p[..., 1] - cl[..., 1]) ** 2
    r = tool.radius
    inside = d2 <= r * r * (1 + 1e-12)
    if tool.kind == "ball":
        h = p[..., 2] + np.sqrt(np.where(inside, np.maximum(r * r - d2, 0.0), 0.0)) - r
    else:
        h = p[..., 2].copy()
    return np.where(inside, h, -np.inf)


def _drop(tool: Tool, cl: np.ndarray, pts: np.ndarray, chunk: int = 4000, sectors: int = 1):
    """Max tip height over samples and the maximizing sample's index (-1 if none),
    ``(N, sectors)``: with ``sectors = 4`` the best sample in each quadrant around the
    CL point (separate seeds for separate local maxima)."""
    from scipy.spatial import cKDTree

    tree = cKDTree(pts[:, :2])
    best = np.full((len(cl), sectors), -np.inf)
    arg = np.full((len(cl), sectors), -1, dtype=np.int64)
    for s in range(0, len(cl), chunk):
        part = cl[s:s + chunk]
        pairs = cKDTree(part).sparse_distance_matrix(tree, tool.radius, output_type="ndarray")
        if not len(pairs):
            continue
        i, j = pairs["i"].astype(np.int64), pairs["j"].astype(np.int64)
        h = _heights(tool, part[i], pts[j])
        if sectors == 4:
            sec = (pts[j, 0] >= part[i, 0]).astype(np.int64) + 2 * (pts[j, 1] >= part[i, 1])
        else:
            sec = np.zeros_like(i)
        key = i * sectors + sec
        order = np.lexsort((h, key))
        key, j, h = key[order], j[order], h[order]
        last = np.r_[key[1:] != key[:-1], True]
        rows, cols = s + key[last] // sectors, key[last] % sectors
        best[rows, cols] = h[last]
        arg[rows, cols] = j[last]
    return (best[:, 0], arg[:, 0]) if sectors == 1 else (best, arg)


def _zoom(tool, model, cl, best, pid, u, v, hu, hv, levels=14, n=5):
    """Refine each CL's maximum on small 5 x 5 (u, v) grids around its seed, halving
    the span each level (handles contacts on face borders and rim/border corners)."""
    for level in range(levels):
        span = 1.0 / 2.0**level
        for k, patch in enumerate(model.patches):
            sel = np.nonzero(pid == k)[0]
            if not sel.size:
                continue
            u0, u1, v0, v1 = patch.bounds
            off = np.linspace(-1, 1, n)
            gu = np.clip(u[sel, None, None] + span * hu[k] * off[None, :, None], u0, u1)
            gv = np.clip(v[sel, None, None] + span * hv[k] * off[None, None, :], v0, v1)
            gu, gv = np.broadcast_arrays(gu, gv)
            flat_u, flat_v = gu.reshape(-1), gv.reshape(-1)
            p = patch.evaluate(flat_u, flat_v, 0)[:, 0, 0].reshape(len(sel), n * n, 3)
            h = _heights(tool, cl[sel, None, :], p)
            inside = model.inside[k]
            if inside is not None:
                h = np.where(inside(flat_u, flat_v).reshape(len(sel), n * n), h, -np.inf)
            a = np.argmax(h, axis=1)
            hb = h[np.arange(len(sel)), a]
            better = hb > best[sel]
            idx = sel[better]
            best[idx] = hb[better]
            u[idx] = gu.reshape(len(sel), -1)[better, a[better]]
            v[idx] = gv.reshape(len(sel), -1)[better, a[better]]
    return best, u, v


def _newton_ball(tool, model, cl, best, pid, u, v, iterations=8):
    """Polish ball-cutter contacts: Newton on grad h = 0, h = z + sqrt(r² − dx² − dy²)."""
    r = tool.radius
    for k, patch, sel in _contacts_by_patch(model, pid, best):
        u0, u1, v0, v1 = patch.bounds
        uu, vv = u[sel].copy(), v[sel].copy()
        for _ in range(iterations):
            d = patch.evaluate(uu, vv, 2)
            S, Su, Sv, Suu, Svv, Suv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1], d[:, 2, 0], d[:, 0, 2], d[:, 1, 1]
            dx, dy = S[:, 0] - cl[sel, 0], S[:, 1] - cl[sel, 1]
            q2 = r * r - dx * dx - dy * dy
            ok = q2 > 1e-6 * r * r
            q = np.sqrt(np.where(ok, q2, 1.0))
            A = dx * Su[:, 0] + dy * Su[:, 1]
            B = dx * Sv[:, 0] + dy * Sv[:, 1]
            gu = Su[:, 2] - A / q
            gv = Sv[:, 2] - B / q
            Au = Su[:, 0] ** 2 + Su[:, 1] ** 2 + dx * Suu[:, 0] + dy * Suu[:, 1]
            Av = Su[:, 0] * Sv[:, 0] + Su[:, 1] * Sv[:, 1] + dx * Suv[:, 0] + dy * Suv[:, 1]
            Bv = Sv[:, 0] ** 2 + Sv[:, 1] ** 2 + dx * Svv[:, 0] + dy * Svv[:, 1]
            huu = Suu[:, 2] - Au / q - A * A / q**3
            huv = Suv[:, 2] - Av / q - A * B / q**3
            hvv = Svv[:, 2] - Bv / q - B * B / q**3
            det = huu * hvv - huv * huv
            good = ok & (np.abs(det) > 1e-300)
            det = np.where(good, det, 1.0)
            su = np.where(good, -(hvv * gu - huv * gv) / det, 0.0)
            sv = np.where(good, -(huu * gv - huv * gu) / det, 0.0)
            # active set: on a face border pushing outwards, optimize along the border
            at_v = ((vv <= v0) & (sv < 0)) | ((vv >= v1) & (sv > 0))
            at_u = ((uu <= u0) & (su < 0)) | ((uu >= u1) & (su > 0))
            only_v = at_v & ~at_u
            only_u = at_u & ~at_v
            su = np.where(only_v & ok & (huu != 0), -gu / np.where(huu != 0, huu, 1.0), su)
            sv = np.where(only_v, 0.0, sv)
            sv = np.where(only_u & ok & (hvv != 0), -gv / np.where(hvv != 0, hvv, 1.0), sv)
            su = np.where(only_u, 0.0, su)
            su = np.where(at_u & at_v, 0.0, su)
            sv = np.where(at_u & at_v, 0.0, sv)
            uu, vv = np.clip(uu + su, u0, u1), np.clip(vv + sv, v0, v1)
        _keep_higher(tool, model, k, cl, sel, uu, vv, best, u, v)
    return best, u, v


def _contacts_by_patch(model, pid, best):
    """``(k, patch, indices)`` for every patch holding found contacts (finite ``best``)."""
    for k, patch in enumerate(model.patches):
        sel = np.nonzero((pid == k) & np.isfinite(best))[0]
        if sel.size:
            yield k, patch, sel


def _keep_higher(tool, model, k, cl, sel, uu, vv, best, u, v) -> None:
    """Where polished contacts ``(uu, vv)`` on patch ``k`` lift the tool higher than the
    current ``best`` (and lie inside the patch's trim), adopt them, in place."""
    h = _heights(tool, cl[sel], model.patches[k].evaluate(uu, vv, 0)[:, 0, 0])
    inside = model.inside[k]
    if inside is not None:
        h = np.where(inside(uu, vv), h, -np.inf)
    better = h > best[sel]
    idx = sel[better]
    best[idx], u[idx], v[idx] = h[better], uu[better], vv[better]


def _newton_flat_rim(tool, model, cl, best, pid, u, v, iterations=10):
    """Polish flat-end-mill rim contacts: maximize S_z subject to |S_xy − cl| = r
    (Newton on the Lagrange system in (u, v, λ))."""
    r = tool.radius
    for k, patch, sel in _contacts_by_patch(model, pid, best):
        u0, u1, v0, v1 = patch.bounds
        uu, vv = u[sel].copy(), v[sel].copy()
        lam = None
        for _ in range(iterations):
            d = patch.evaluate(uu, vv, 2)
            S, Su, Sv, Suu, Svv, Suv = d[:, 0, 0], d[:, 1, 0], d[:, 0, 1], d[:, 2, 0], d[:, 0, 2], d[:, 1, 1]
            dx, dy = S[:, 0] - cl[sel, 0], S[:, 1] - cl[sel, 1]
            A = dx * Su[:, 0] + dy * Su[:, 1]
            B = dx * Sv[:, 0] + dy * Sv[:, 1]
            Au = Su[:, 0] ** 2 + Su[:, 1] ** 2 + dx * Suu[:, 0] + dy * Suu[:, 1]
            Av = Su[:, 0] * Sv[:, 0] + Su[:, 1] * Sv[:, 1] + dx * Suv[:, 0] + dy * Suv[:, 1]
            Bv = Sv[:, 0] ** 2 + Sv[:, 1] ** 2 + dx * Svv[:, 0] + dy * Svv[:, 1]
            if lam is None:
                lam = (Su[:, 2] * A + Sv[:, 2] * B) / np.maximum(2 * (A * A + B * B), 1e-300)
            F = np.stack([Su[:, 2] - 2 * lam * A, Sv[:, 2] - 2 * lam * B, dx * dx + dy * dy - r * r], axis=1)
            J = np.empty((len(sel), 3, 3))
            J[:, 0] = np.stack([Suu[:, 2] - 2 * lam * Au, Suv[:, 2] - 2 * lam * Av, -2 * A], axis=1)
            J[:, 1] = np.stack([Suv[:, 2] - 2 * lam * Av, Svv[:, 2] - 2 * lam * Bv, -2 * B], axis=1)
            J[:, 2] = np.stack([2 * A, 2 * B, np.zeros_like(A)], axis=1)
            det = np.linalg.det(J)
            good = np.abs(det) > 1e-300
            J[~good] = np.eye(3)
            step = -np.linalg.solve(J, np.where(good[:, None], F, 0.0)[..., None])[..., 0]
            uu, vv, lam = np.clip(uu + step[:, 0], u0, u1), np.clip(vv + step[:, 1], v0, v1), lam + step[:, 2]
        _keep_higher(tool, model, k, cl, sel, uu, vv, best, u, v)
    return best, u, v


def _refine(tool, model, cl, best, pid, u, v, hu, hv):
    best, u, v = _zoom(tool, model, cl, best, pid, u, v, hu, hv)
    if tool.kind == "ball":
        return _newton_ball(tool, model, cl, best, pid, u, v)
    # flat end: interior tops (grad S_z = 0) are found by the zoom; rims by Lagrange-Newton
    return _newton_flat_rim(tool, model, cl, best, pid, u, v)


def _seeded(best, arg, pid_s, us, vs):
    hit = arg >= 0
    j = np.maximum(arg, 0)
    return np.where(hit, pid_s[j], -1), np.where(hit, us[j], 0.0), np.where(hit, vs[j], 0.0)


def drop_cutter(obj, tool: Tool, xy, *, spacing: float | None = None, progress: bool = False,
                chunk: int = 1000, _model_cache=None):
    """Tool-tip heights ``(N,)`` and contact points ``(N, 3)`` of ``tool`` dropped onto
    ``obj`` at the (x, y) locations ``xy`` ``(N, 2)`` (NaN where the tool misses).
    CL points are processed in blocks of ``chunk`` (a tqdm bar with ``progress``)."""
    if not isinstance(tool, Tool):
        raise SurfmodError(f"tool: expected a surfmod Tool, got {type(tool).__name__}")
    cl_all = checks.finite_array(xy, "xy", ndim=2, last=2)
    model = _model_cache or _model(obj)
    spacing = tool.radius / 4 if spacing is None else checks.positive(spacing, "spacing")
    pts, pid_s, us, vs, hu, hv = _samples(model, spacing)
    z = np.full(len(cl_all), np.nan)
    contacts = np.full((len(cl_all), 3), np.nan)
    starts = range(0, len(cl_all), chunk)
    if progress:
        from tqdm import tqdm

        starts = tqdm(starts, desc="drop-cutter", unit="block")
    for s0 in starts:
        cl = cl_all[s0:s0 + chunk]
        bests, args = _drop(tool, cl, pts, sectors=4)
        best = np.full(len(cl), -np.inf)
        pid, u, v = np.full(len(cl), -1), np.zeros(len(cl)), np.zeros(len(cl))
        for q in range(4):  # one seed per quadrant: separate local maxima are all refined
            sel = np.nonzero(args[:, q] >= 0)[0]
            if not sel.size:
                continue
            pq, uq, vq = _seeded(bests[sel, q], args[sel, q], pid_s, us, vs)
            bq, uq, vq = _refine(tool, model, cl[sel], bests[sel, q].copy(), pq, uq, vq, hu, hv)
            take = bq > best[sel]
            t = sel[take]
            best[t], pid[t], u[t], v[t] = bq[take], pq[take], uq[take], vq[take]
        for k, patch in enumerate(model.patches):
            sel = np.nonzero(pid == k)[0]
            if sel.size:
                contacts[s0 + sel] = patch.evaluate(u[sel], v[sel], 0)[:, 0, 0]
        z[s0:s0 + len(cl)] = np.where(np.isfinite(best), best, np.nan)
    return z, contacts


def gouge_depth(tool: Tool, points: np.ndarray, model: _Model, spacing: float) -> float:
    """Deepest penetration of the tool at the CL ``points`` into an independent dense
    sample of the exact surface (half-step shifted grid); ≤ 0 means no gouge."""
    pts = _samples(model, spacing, shift=0.5)[0]
    h, _ = _drop(tool, points[:, :2], pts)
    ok = np.isfinite(h)
    return float(np.max(h[ok] - points[ok, 2])) if ok.any() else float("-inf")


def _raster(lo, hi, stepover, step, direction):
    a, b = (0, 1) if direction == "x" else (1, 0)
    n_pass = int(np.ceil((hi[b] - lo[b]) / stepover - 1e-9)) + 1
    across = np.linspace(lo[b], hi[b], max(n_pass, 2)) if hi[b] > lo[b] else np.array([lo[b]])
    n_along = int(np.ceil((hi[a] - lo[a]) / step - 1e-9)) + 1
    along = np.linspace(lo[a], hi[a], max(n_along, 2))
    rows, index = [], []
    for k, c in enumerate(across):
        line = along if k % 2 == 0 else along[::-1]
        pts = np.empty((len(line), 2))
        pts[:, a], pts[:, b] = line, c
        if k:  # link from the previous pass along the boundary, drop-cut too
            prev = rows[-1][-1]
            m = int(np.ceil(abs(c - prev[b]) / step - 1e-9))
            if m > 1:
                link = np.empty((m - 1, 2))
                link[:, a] = prev[a]
                link[:, b] = prev[b] + (c - prev[b]) * np.arange(1, m) / m
                rows.append(link)
                index.append(np.full(m - 1, -1))
        rows.append(pts)
        index.append(np.full(len(line), k))
    return np.concatenate(rows), np.concatenate(index), across


def toolpath(obj, tool: Tool, stepover: float | None = None, *, scallop: float | None = None,
             step: float | None = None, direction: str = "x", bounds=None, check: bool = True,
             progress: bool = False, max_points: int = 2_000_000) -> Toolpath:
    """Zig-zag drop-cutter finishing path of ``tool`` over a surface or a solid's top.

    ``obj``: a surfmod surface (or list of them) machined from above, a build123d solid
    or a STEP path (its upward-facing faces).  Give ``stepover`` (distance between
    passes, at most the tool diameter) or ``scallop`` (cusp height on flat ground for a
    ball cutter, stepover = 2·sqrt(2rh − h²)).  ``step`` is the spacing of CL points
    along a pass (default ``radius / 4``); passes run along ``direction`` ``"x"`` or
    ``"y"`` over the part's (x, y) bounding box or ``bounds = ((xmin, ymin), (xmax, ymax))``.
    ``check`` measures the gouge on an independent denser sample; ``progress`` shows a
    tqdm bar over blocks of cutter locations.  More than ``max_points`` cutter locations
    (estimated from the bounds, stepover and step before anything is allocated) are
    refused; raise ``max_points`` to allow them.

    >>> import surfmod as sm, numpy as np
    >>> s = sm.plane((0, 0, 1), (10, 0, 1), (0, 10, 1))
    >>> tp = sm.toolpath(s, sm.Tool("ball", 2.0), scallop=0.05)
    >>> bool(tp.stepover <= 2 * np.sqrt(2 * 2 * 0.05 - 0.05 ** 2)), float(np.abs(tp.points[:, 2] - 1).max()) < 1e-12
    (True, True)
    """
    if not isinstance(tool, Tool):
        raise SurfmodError(f"tool: expected a surfmod Tool, got {type(tool).__name__}")
    if stepover is not None and scallop is not None:
        raise SurfmodError("stepover: give either stepover or scallop, not both")
    if scallop is not None:
        stepover = tool.stepover_for_scallop(scallop)
    elif stepover is None:
        raise SurfmodError("stepover: give stepover or scallop")
    else:
        stepover = checks.positive(stepover, "stepover")
    if stepover > tool.diameter:
        raise SurfmodError(f"stepover: {stepover:g} is larger than the tool diameter {tool.diameter:g}")
    step = tool.radius / 4 if step is None else checks.positive(step, "step")
    if direction not in ("x", "y"):
        raise SurfmodError(f"direction: expected 'x' or 'y', got {direction!r}")
    model = _model(obj)
    spacing = min(tool.radius / 4, stepover / 2, step)
    if bounds is None:
        pts = _samples(model, spacing * 4)[0]
        lo, hi = pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)
    else:
        b = checks.finite_array(bounds, "bounds")
        if b.shape != (2, 2) or np.any(b[1] < b[0]):
            raise SurfmodError(f"bounds: expected ((xmin, ymin), (xmax, ymax)), got {b.tolist()}")
        lo, hi = b[0], b[1]
    a, b = (0, 1) if direction == "x" else (1, 0)
    passes = (float(hi[b] - lo[b]) / stepover + 2) if np.isfinite(hi[b] - lo[b]) else np.inf
    along = (float(hi[a] - lo[a]) / step + 2) if np.isfinite(hi[a] - lo[a]) else np.inf
    checks.work(passes * along + passes * stepover / step, max_points, "max_points",
                f"the raster of {passes:,.0f} passes x {along:,.0f} points (use a larger step or stepover)")
    xy, index, across = _raster(lo, hi, stepover, step, direction)
    z, contacts = drop_cutter(obj, tool, xy, spacing=spacing, progress=progress, _model_cache=model)
    if np.isnan(z).all():
        raise SurfmodError("bounds: the tool touches no surface inside these bounds")
    z = np.where(np.isnan(z), np.nanmin(z), z)  # outside the part: stay at the lowest level
    points = np.column_stack([xy, z])
    gouge = gouge_depth(tool, points, model, spacing / 1.5) if check else float("nan")
    actual = float(np.diff(across).max()) if len(across) > 1 else 0.0
    return Toolpath(checks.frozen(points), checks.frozen(contacts), index, tool, actual, step,
                    tool.scallop_for_stepover(actual), direction, gouge)
