"""The exact part as points, what a program is judged against (:mod:`surfmod.cam.verify`)
and what a tool path's last repair holds its moves against (:func:`lift_gouges`).

Every face is read back (:func:`surfmod.from_face`) and evaluated on a parameter grid a
``spacing`` apart on the surface, closer where it curves (up to ``MAX_REFINE`` times),
kept inside its trim; every edge that bounds a face is sampled as finely (edges bounding
no face are construction wires, not material).  The points are bucketed on an (x, y) grid
(:class:`PartPoints`) for the compiled probes of :mod:`surfmod.cam.verify_kernels`.  The
last sampling is kept (:func:`sampled_part`), so a path's repair and its verdict sample
the part once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from .. import checks
from ..errors import SurfmodError
from ..readback.trimmed import from_face
from . import verify_kernels as K

#: points on the part, probes along the moves and stock nodes one verification may take
MAX_SAMPLES = 30_000_000
MAX_PROBES = 60_000_000
#: the least upward share of a contact normal a lift counts on (beside a vertical wall a
#: lift frees nothing: it rises twenty times the depth there)
MIN_RISE_SHARE = 0.05
#: grid points per face direction, at most, and how much closer than the tool asks a
#: curved face's points may stand
MAX_FACE_GRID = 4000
MAX_REFINE = 4.0
#: samples per edge of the boundary loops that settle the points far from the trim, and
#: the grids small enough to classify point by point instead
BOUNDARY_SAMPLES = 64
SMALL_FACE = 4096


@dataclass(frozen=True)
class PartPoints:
    """Points of the exact part bucketed on an (x, y) grid of ``cell``: ``points`` sorted
    by cell, highest first in each, then by x and y, so that their order is a function of
    the points alone (whatever order they come in, the walls' nearest points
    (:func:`~surfmod.cam.wall_dexels.feet`) break their ties alike); ``starts`` the
    cells' offsets (``nx * ny + 1``)."""

    points: np.ndarray
    starts: np.ndarray
    origin: tuple
    cell: float
    shape: tuple

    @classmethod
    def bucket(cls, points: np.ndarray, cell: float) -> "PartPoints":
        lo = points[:, :2].min(axis=0) - cell
        nx, ny = (np.floor((points[:, :2].max(axis=0) - lo) / cell).astype(np.int64) + 2)
        ij = np.floor((points[:, :2] - lo) / cell).astype(np.int64)
        cid = ij[:, 0] * ny + ij[:, 1]
        order = np.lexsort((points[:, 1], points[:, 0], -points[:, 2], cid))
        starts = np.searchsorted(cid[order], np.arange(nx * ny + 1))
        return cls(np.ascontiguousarray(points[order]), starts.astype(np.int64), (float(lo[0]), float(lo[1])),
                   float(cell), (int(nx), int(ny)))

    def deepest(self, probes: np.ndarray, radius: float, corner: float):
        return K.deepest(self.starts, self.points, *self.origin, self.cell, *self.shape,
                         np.ascontiguousarray(probes, dtype=float), radius, corner)

    def around(self, q: np.ndarray, rings: int) -> np.ndarray:
        """The points of the buckets within ``rings`` buckets of those holding the points
        ``q`` (their (x, y); outside the grid: its nearest bucket)."""
        nx, ny = self.shape
        ij = np.floor((q[:, :2] - np.array(self.origin)) / self.cell).astype(np.int64)
        mask = np.zeros((nx, ny), bool)
        mask[np.clip(ij[:, 0], 0, nx - 1), np.clip(ij[:, 1], 0, ny - 1)] = True
        mask = ndimage.binary_dilation(mask, structure=np.ones((3, 3), bool), iterations=rings)
        return self.points[np.repeat(mask.ravel(), np.diff(self.starts))]

    def drop(self, xy: np.ndarray, radius: float, corner: float) -> np.ndarray:
        return K.drop_heights(self.starts, self.points, *self.origin, self.cell, *self.shape,
                              np.ascontiguousarray(xy, dtype=float), radius, corner)


def _face_grid(face, spacing: float, sag: float | None = None):
    """A face's parameter grid ``spacing`` apart on the surface (from its largest
    derivatives on a 9 x 9 grid), closer where the face curves so much that it leaves the
    points' chords by more than ``sag`` (``spacing² κ / 8``, κ from the second
    derivatives there), at most ``MAX_FACE_GRID`` a side."""
    (u0, u1), (v0, v1) = face.domain
    uu, vv = np.meshgrid(np.linspace(u0, u1, 9), np.linspace(v0, v1, 9), indexing="ij")
    d = face.derivatives(uu.ravel(), vv.ravel(), 2 if sag else 1)
    su_n = np.linalg.norm(d[:, 1, 0], axis=1)
    sv_n = np.linalg.norm(d[:, 0, 1], axis=1)
    if sag:
        # away from degenerate points (a pole's vanishing derivative is no curvature), and
        # at most MAX_REFINE times closer than the tool asks
        ok = (su_n > 1e-3 * su_n.max()) & (sv_n > 1e-3 * sv_n.max())
        if ok.any():
            su_k, sv_k = su_n[ok], sv_n[ok]
            kappa = max(float(np.max(np.linalg.norm(d[ok, 2, 0], axis=1) / su_k ** 2)),
                        float(np.max(np.linalg.norm(d[ok, 0, 2], axis=1) / sv_k ** 2)),
                        float(np.max(np.linalg.norm(d[ok, 1, 1], axis=1) / (su_k * sv_k))))
            if np.isfinite(kappa) and kappa > 0:
                spacing = max(min(spacing, math.sqrt(8.0 * sag / kappa)), spacing / MAX_REFINE)
    su = float(su_n.max()) * (u1 - u0)
    sv = float(sv_n.max()) * (v1 - v0)
    nu = int(min(MAX_FACE_GRID, max(2, math.ceil(su / spacing) + 1)))
    nv = int(min(MAX_FACE_GRID, max(2, math.ceil(sv / spacing) + 1)))
    return np.linspace(u0, u1, nu), np.linspace(v0, v1, nv)


def _crossings(loops: list, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """Even-odd inside of the closed polylines ``loops`` on the grid ``us x vs``: per grid
    line ``v``, the polylines' crossings left of each ``u`` counted (half-open in v)."""
    segs = np.concatenate([np.stack([lp, np.roll(lp, -1, axis=0)], axis=1) for lp in loops])
    (au, av), (bu, bv) = segs[:, 0].T, segs[:, 1].T
    out = np.zeros((len(us), len(vs)), bool)
    for j, v in enumerate(vs):
        hit = (av <= v) != (bv <= v)
        if not hit.any():
            continue
        a_u, a_v, b_u, b_v = au[hit], av[hit], bu[hit], bv[hit]
        cross = np.sort(a_u + (v - a_v) * (b_u - a_u) / (b_v - a_v))
        out[:, j] = np.searchsorted(cross, us, side="right") % 2 == 1
    return out


def _inside(face, us: np.ndarray, vs: np.ndarray) -> np.ndarray:
    """The grid ``us x vs`` classified against the face's trim.  The boundary loops are
    sampled from the exact p-curves; the polylines (even-odd over the loops) settle every
    point farther from them than their sagitta (estimated from the samples halfway) plus
    a grid diagonal, in grid steps; OCCT's classifier the points nearer the boundary."""
    uu, vv = np.meshgrid(us, vs, indexing="ij")
    pts = np.column_stack([uu.ravel(), vv.ravel()])
    if len(pts) <= SMALL_FACE:  # fewer points than its boundary samples: ask them all
        return face.contains(pts[:, 0], pts[:, 1]).reshape(uu.shape)
    # an odd count per edge puts every joint of two edges at an even index: each odd
    # sample is its edge's p-curve at the parameter halfway between its neighbours
    loops = [lp for lp in face.boundary_loops(2 * BOUNDARY_SAMPLES + 1) if len(lp) >= 5]
    if not loops or len(us) < 2 or len(vs) < 2:
        return face.contains(pts[:, 0], pts[:, 1]).reshape(uu.shape)
    inside = _crossings(loops, us, vs).ravel()
    # distances in grid steps (u and v differ in units and scale)
    scale = np.array([us[1] - us[0], vs[1] - vs[0]])
    grid_loops = [lp / scale for lp in loops]
    # the halfway samples' distance from their neighbours' chords bounds the sagitta of
    # the polylines above (halving a chord quarters it)
    sag = max(float(np.linalg.norm(lp[1:-1:2] - 0.5 * (lp[:-2:2] + lp[2::2]), axis=1).max(initial=0.0))
              for lp in grid_loops)
    # samples along the polylines at most a grid step apart
    dense = [probes_along(lp[:-1], lp[1:], 1.0, MAX_PROBES)[0] for lp in grid_loops]
    dist, _ = cKDTree(np.concatenate(dense)).query(pts / scale, distance_upper_bound=sag + 2.0)
    ask = np.isfinite(dist)
    if ask.any():
        inside[ask] = face.contains(pts[ask, 0], pts[ask, 1])
    return inside.reshape(uu.shape)


def part_points(shape, spacing: float, max_samples: int = MAX_SAMPLES, sag: float | None = None, *,
                fit: bool = False) -> np.ndarray:
    """``(points (N, 3), spacing)``: points on every face of ``shape`` inside its trim and
    on every edge that bounds a face, about ``spacing`` apart (closer on faces curved so
    much that they leave the points' chords by more than ``sag``), and the spacing used.  More than ``max_samples`` (counted on the
    faces' parameter grids before any is evaluated) raises ``SurfmodError``; with ``fit``
    the points stand farther apart instead, as many as the cap allows (see
    :func:`sampled_part`)."""
    from ..occ.sample import edge_length, sample_curve
    from ..occ.topo import curve_of_edge, faces_of, geometric_edges, wrapped

    spacing = checks.positive(spacing, "spacing")
    faces = [from_face(f) for f in faces_of(shape)]
    edges = [e for _, e, owners in geometric_edges(wrapped(shape)) if owners]
    lengths = [edge_length(e) for e in edges]

    def plan(spacing, sag):
        grids = [_face_grid(f, spacing, sag) for f in faces]
        counts = [max(2, math.ceil(length / spacing) + 1) for length in lengths]
        return grids, counts, sum(len(a) * len(b) for a, b in grids) + sum(counts)

    grids, counts, total = plan(spacing, sag)
    if fit and total > max_samples:  # a count grows as 1/spacing² at most
        grow = 1.1 * math.sqrt(total / max_samples)
        spacing, sag = spacing * grow, None if sag is None else sag * grow * grow
        grids, counts, total = plan(spacing, sag)
    checks.work(total, max_samples, "max_samples",
                f"the verification's {total:,} points on the part, {spacing:.3g} mm apart "
                f"(a larger scallop or tolerance, or no verification)")
    out = []
    for face, (us, vs) in zip(faces, grids):
        uu, vv = np.meshgrid(us, vs, indexing="ij")
        inside = _inside(face, us, vs).ravel()
        if inside.any():
            out.append(face.points(uu.ravel()[inside], vv.ravel()[inside], max_points=max_samples))
    for edge, n in zip(edges, counts):
        curve, t0, t1 = curve_of_edge(edge)
        out.append(sample_curve(curve, t0, t1, n))
    if not out:
        raise SurfmodError("part: has no faces to verify against")
    return np.concatenate(out), spacing


def spacing_for(limit: float, radius: float, corner: float) -> float:
    """Point spacing on the part for judging a tool of ``radius``/``corner`` to ``limit``:
    the gap a surface can close between points, ``spacing² / (8 c)``, at most half of it."""
    c = max(corner, limit)
    return float(min(2.0 * math.sqrt(limit * c), radius / 4))


def bucket_cell(spacing: float, radius: float) -> float:
    """Bucket size: a quarter of the smallest tool radius (a probe reads about 80 cells,
    most of them cut short by their nearest distance), at least a few points wide."""
    return max(radius / 4, 3 * spacing)


def coarser_note(spacing: float, asked: float, cap: int) -> list[str]:
    """The note a verdict carries when its points had to stand farther apart than asked."""
    if spacing <= asked:
        return []
    return [f"note: the points stand {spacing:.3g} mm apart, coarser than the {asked:.3g} the limits ask "
            f"({cap:,} at most): between them a face may come nearer a tool than measured"]


_SAMPLED: dict = {}


def sampled_part(shape, spacing: float, cell: float, max_samples: int = MAX_SAMPLES,
                 sag: float | None = None, fit: bool = False) -> tuple:
    """``(PartPoints, spacing)``: :func:`part_points` of ``shape`` bucketed by ``cell``, and
    the spacing they stand at (larger than asked with ``fit`` when the cap binds); the
    last one is kept, so a path's repair and its verdict sample the part once."""
    from ..occ.topo import wrapped

    occ = wrapped(shape)
    key = (hash(occ), float(spacing), float(cell), sag, fit, max_samples)
    # the entry holds its shape, so no other shape can take its address (and its hash)
    # while it is kept; equal shapes share the geometry, hence the points
    entry = _SAMPLED.get(key)
    if entry is None or not entry[2].IsEqual(occ):
        _SAMPLED.clear()
        points, used = part_points(shape, spacing, max_samples, sag, fit=fit)
        entry = _SAMPLED[key] = (PartPoints.bucket(points, cell), used, occ)
    return entry[0], entry[1]


def lift_gouges(shape, points: np.ndarray, cutter, limit: float, *, rounds: int = 3,
                max_samples: int = MAX_SAMPLES, max_probes: int = MAX_PROBES):
    """The cutter locations ``points`` (N, 3) of one continuous path with every move that
    brings the exact part's points deeper than half ``limit`` into the tool lifted (the
    points between the samples can come nearer by about a quarter of it): both its ends
    raised until that depth is a quarter of the limit, then measured again, at most
    ``rounds`` times (the lift leaves material, never cuts).  Returns ``(points, lift (N,))``."""
    points = np.array(points, dtype=float)
    spacing = spacing_for(limit / 2, cutter.radius, cutter.corner)
    part, spacing = sampled_part(shape, spacing, bucket_cell(spacing, cutter.radius), max_samples, limit / 4, fit=True)
    lift = np.zeros(len(points))
    for _ in range(rounds):
        probes, move, _ = probes_along(points[:-1], points[1:], spacing, max_probes)
        depth, which = part.deepest(probes, cutter.radius, cutter.corner)
        # each move's deepest probe (the last of its group sorted by depth)
        order = np.lexsort((depth, move))
        last = order[np.r_[move[order][1:] != move[order][:-1], True]]
        bad_probe = last[depth[last] > 0.5 * limit]
        if not len(bad_probe):
            break
        # a vertical lift frees the tool by the rise times the upward share of the contact
        # normal (from the point to the corner's centre): little beside a wall, so more there
        q = part.points[which[bad_probe]]
        centre = probes[bad_probe] + [0.0, 0.0, cutter.corner]
        normal_z = (centre[:, 2] - q[:, 2]) / np.maximum(np.linalg.norm(centre - q, axis=1), 1e-300)
        rise = (depth[bad_probe] - 0.25 * limit) / np.clip(normal_z, MIN_RISE_SHARE, 1.0)
        bad = move[bad_probe]
        up = np.zeros(len(points))
        np.maximum.at(up, bad, rise)
        np.maximum.at(up, bad + 1, rise)
        points[:, 2] += up
        lift += up
    return points, lift


def probes_along(start: np.ndarray, end: np.ndarray, spacing: float, max_probes: int):
    """Points at most ``spacing`` apart along each move (both ends included), each one's
    move, and the spacing used: wider than asked where ``max_probes`` would be passed, so a
    long program is judged more coarsely (and says so), never refused."""
    spacing = probe_spacing(start, end, spacing, max_probes)
    n = np.ceil(np.linalg.norm(end - start, axis=1) / spacing).astype(np.int64) + 1
    total = int(n.sum())
    checks.work(total, max_probes, "max_probes", f"the verification's {total:,} probes, two per move at the least")
    move = np.repeat(np.arange(len(start)), n)
    first = np.r_[0, np.cumsum(n)[:-1]]
    t = (np.arange(total) - np.repeat(first, n)) / np.maximum(np.repeat(n - 1, n), 1)
    pts = start[move] + t[:, None] * (end - start)[move]
    return pts, move, spacing


def probe_spacing(start: np.ndarray, end: np.ndarray, spacing: float, max_probes: int) -> float:
    """The probes' spacing along the moves: ``spacing``, or wider where ``max_probes`` would be passed."""
    length = np.linalg.norm(end - start, axis=1)
    if (np.ceil(length / spacing) + 1).sum() > max_probes and 2 * len(start) < max_probes:
        return max(spacing, float(length.sum()) / (max_probes - 2 * len(start)))
    return spacing
