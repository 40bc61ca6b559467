"""Rest machining: a smaller tool cuts only where the operations before it left more than
the scallop above the part.

Where is read from the job's own stock model (:class:`StockModel`, swept as the verifier
sweeps): a node is left where the stock's top lies farther than the scallop plus the
tolerance from every triangle, in 3D (:func:`left_over`).  :func:`rest_moves` runs the
finishing's contours on each region's steep part, then drop-cutter rasters along x and y
clipped to it, linked as the finishing links.  See :doc:`/guide/cam` (section "Rest machining").
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from .. import checks
from ..errors import SurfmodError
from . import verify_kernels as K
from .finishing import RECUT_SHARE, REST_CLEARANCE, STEEP_MARGIN, add_raster, contour_moves, contour_spacing, \
    height_field, judge_links, near_box
from .roughing import RAPID, Motion, Moves
from .stock_field import NodeGrid
from .tool import Tool
from .toolpath import MeshedPart, raster_path
from .verify import MAX_NODES, stock_cells
from .waterline import MAX_PAIRS, fiber_pairs

#: raster runs this many tool radii apart along the raster are joined by its own moves
BRIDGE_RADII = 4.0
#: raster locations the rest passes may take, estimated from the regions before any drop;
#: the thickness test may take PAIRS_PER_POINT (node, triangle) pairs per location of it
MAX_LOCATIONS = 2_000_000
PAIRS_PER_POINT = 100
#: (node, triangle) pairs of the thickness test measured at once
PAIR_BLOCK = 2_000_000
#: the rest region's slopes (degrees) from which contours finish it: the rasters' passes,
#: ``cos 45°`` of the stepover apart, hold the scallop on slopes across them up to this
STEEP_ANGLE = 45.0


class StockModel(NodeGrid):
    """The job's stock as a height field: ``top[i, j]`` over the node
    ``lo + cell * (i, j)`` of the stock box (``origin``: its x and y); :meth:`sweep`
    lowers it along a motion."""

    def __init__(self, stock: np.ndarray, cell: float, max_nodes: int = MAX_NODES):
        self.lo = np.asarray(stock, float)[0]
        self.origin = (float(self.lo[0]), float(self.lo[1]))
        self.cell, nx, ny, self.note = stock_cells(stock, cell, max_nodes)
        self.top = np.full((nx, ny), float(np.asarray(stock, float)[1, 2]))

    @property
    def sag(self) -> float:
        """How far the stamped sweep can stand above the true one (stamps half a cell
        apart: the profile's sag over a quarter cell, for a corner radius of a cell or
        more, as the verifier bounds it)."""
        return (self.cell / 4) ** 2 / (2 * self.cell)

    def index(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The indices ``(i, j)`` of the node nearest each ``xy`` (N, 2), beyond the grid too."""
        return (np.rint((xy[:, 0] - self.lo[0]) / self.cell).astype(int),
                np.rint((xy[:, 1] - self.lo[1]) / self.cell).astype(int))

    def at(self, a: np.ndarray, xy: np.ndarray, off) -> np.ndarray:
        """The field ``a`` (on the nodes) at the node nearest each ``xy``, ``off`` beyond the grid."""
        i, j = self.index(xy)
        nx, ny = a.shape
        on = (i >= 0) & (i < nx) & (j >= 0) & (j < ny)
        out = np.full(len(xy), off, a.dtype)
        out[on] = a[i[on], j[on]]
        return out

    def part_top(self, triangles: np.ndarray) -> np.ndarray:
        """The part's top (a vertical ray onto ``triangles``) over the nodes, -inf off the part."""
        return height_field(triangles, self.x, self.y)

    def sweep(self, motion: Motion, tool: Tool) -> None:
        """Cut the stock along ``motion`` with ``tool`` (rapids cut nothing)."""
        p = np.ascontiguousarray(motion.points, float)
        if len(p) < 2:
            return
        n = len(p) - 1
        K.sweep_stock(self.top, float(self.lo[0]), float(self.lo[1]), self.cell, np.ascontiguousarray(p[:-1]),
                      np.ascontiguousarray(p[1:]), np.asarray(motion.kind[1:] == RAPID), np.full(n, tool.radius),
                      np.full(n, tool.corner), self.cell / 2)


def point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distance from each point ``p`` (N, 3) to its triangle ``tri`` (N, 3, 3): to the
    plane where the point's foot lies inside, else to the nearest of the three edges
    (a degenerate triangle is its edges).

    >>> tri = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]] * 3, float)
    >>> point_triangle_distance(np.array([[0.5, 0.5, 3.0], [3.0, 0.0, 0.0], [-1.0, -1.0, 1.0]]), tri).round(6).tolist()
    [3.0, 1.0, 1.732051]
    """
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    v0, v1, w = b - a, c - a, p - a
    d00, d01, d11 = (v0 * v0).sum(1), (v0 * v1).sum(1), (v1 * v1).sum(1)
    d20, d21 = (w * v0).sum(1), (w * v1).sum(1)
    den = d00 * d11 - d01 * d01
    ok = den > 1e-300 * np.maximum(d00 * d11, 1e-300)
    den = np.where(ok, den, 1.0)
    s, t = (d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den
    inside = ok & (s >= 0) & (t >= 0) & (s + t <= 1)
    n = np.cross(v0, v1)
    plane = np.abs((w * n).sum(1)) / np.where(ok, np.linalg.norm(n, axis=1), 1.0)
    edge = np.full(len(p), np.inf)
    for s0, e in ((a, v0), (a, v1), (b, c - b)):
        q = p - s0
        ee = (e * e).sum(1)
        u = np.clip((q * e).sum(1) / np.where(ee > 0, ee, 1.0), 0.0, 1.0)
        edge = np.minimum(edge, np.linalg.norm(q - u[:, None] * e, axis=1))
    return np.where(inside, plane, edge)


def left_over(stock: StockModel, part_top: np.ndarray, part: MeshedPart, threshold: float, max_pairs: int):
    """Where the stock model holds material thicker than ``threshold`` on the part: a
    node over the part is left when the stock's top there lies farther than it from
    every triangle (measured in 3D, so the flank of a wall the stock hugs is thin however
    tall, and the fillet a ball left in a corner is thick).  The triangles tried at a
    node are those of ``part``'s drop grid (all within the tool's radius in (x, y));
    their (node, triangle) pairs, counted before any distance, may be at most
    ``max_pairs``.  Returns ``(mask, stats)``, stats ``area`` (mm²), ``max`` (the highest
    left node's height above the part, vertical, mm) and ``regions``."""
    height = np.where(np.isfinite(part_top), stock.top - part_top, -np.inf)
    mask = height > threshold  # a thickness above the threshold needs a height above it first
    if mask.any():
        X, Y = np.meshgrid(stock.x, stock.y, indexing="ij")
        q = np.column_stack([X[mask], Y[mask], stock.top[mask]])
        grid = part.grid
        start, stop = grid.segments(q[:, :2])
        n = np.maximum(stop - start, 0)
        checks.work(int(n.sum()), max_pairs, "max_points",
                    f"the rest's thickness test of {len(q):,} stock nodes against the triangles near each "
                    f"(a hundred pairs per raster location of max_points)")
        near = np.full(len(q), np.inf)
        done = np.r_[0, np.cumsum(n)]
        lo = 0
        while lo < len(q):  # blocks of about PAIR_BLOCK pairs, at least one node each
            hi = max(int(np.searchsorted(done, done[lo] + PAIR_BLOCK, "right")) - 1, lo + 1)
            qi, ti = grid.pairs(q[lo:hi, :2], start[lo:hi], stop[lo:hi])
            np.minimum.at(near, lo + qi, point_triangle_distance(q[lo + qi], grid.triangles[ti]))
            lo = hi
        mask[mask] = near > threshold
    regions = int(ndimage.label(mask, structure=np.ones((3, 3)))[1]) if mask.any() else 0
    stats = {"area": float(mask.sum()) * stock.cell ** 2, "max": float(height[mask].max()) if mask.any() else 0.0,
             "regions": regions}
    return mask, stats


class AboveStock:
    """The height above which the stock model holds no material over a tool's footprint at
    ``xy`` (its highest node within the ``radius`` and a cell), plus the clearance, at most
    ``safe``: where a rest operation's links enter and leave."""

    def __init__(self, stock: StockModel, radius: float, safe: float):
        n = int(math.ceil(radius / stock.cell)) + 1
        di, dj = np.mgrid[-n:n + 1, -n:n + 1]
        self.high = ndimage.maximum_filter(stock.top, footprint=np.hypot(di, dj) <= n, mode="nearest")
        self.stock, self.safe = stock, safe

    def __call__(self, xy) -> np.ndarray:
        i, j = self.stock.index(np.asarray(xy, float).reshape(-1, 2))
        nx, ny = self.high.shape
        return np.minimum(self.high[np.clip(i, 0, nx - 1), np.clip(j, 0, ny - 1)] + REST_CLEARANCE, self.safe)


def _runs(inside: np.ndarray, points: np.ndarray, bridge: float) -> list[tuple[int, int]]:
    """Index ranges ``[a, b)`` of the raster's runs inside, each grown by a point at either
    end, runs less than ``bridge`` apart along the raster joined.

    >>> _runs(np.array([0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1], bool), np.c_[np.arange(11.0), np.zeros((11, 2))], 2.5)
    [(0, 7), (9, 11)]
    """
    flags = np.r_[False, inside, False].astype(np.int8)
    starts = np.flatnonzero(np.diff(flags) == 1)
    ends = np.flatnonzero(np.diff(flags) == -1)
    along = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))]
    out = []
    for a, b in zip(starts, ends):
        a, b = max(int(a) - 1, 0), min(int(b) + 1, len(points))
        if out and along[a] - along[out[-1][1] - 1] <= bridge:
            out[-1] = (out[-1][0], b)
        else:
            out.append((a, b))
    return [(a, b) for a, b in out if b - a >= 2]


class _LeftNear:
    """Whether a contour point at ``xy``, tip height ``z``, of the rest region ``label``
    can meet what the stock model shows left: a left node within the tool's radius and a
    cell of ``xy`` (the region's reach) whose stock stands above ``z``.  ``high`` is the
    highest left stock within that reach of each node (-inf beyond every region)."""

    def __init__(self, stock: StockModel, mask: np.ndarray, disc: np.ndarray, labels: np.ndarray):
        self.high = ndimage.maximum_filter(np.where(mask, stock.top, -np.inf), footprint=disc, mode="constant",
                                           cval=-np.inf)
        self.stock, self.labels, self.label = stock, labels, 0

    def __call__(self, xy: np.ndarray, z: float) -> np.ndarray:
        return (self.stock.at(self.labels, xy, 0) == self.label) & (self.stock.at(self.high, xy, -np.inf) > z)


def rest_moves(part: MeshedPart, tool: Tool, stock: StockModel, mask: np.ndarray, *, scallop: float, stepover: float,
               tolerance: float, safe: float, bottom: float, max_points: int = MAX_LOCATIONS):
    """The rest tool's moves over the nodes of ``mask`` (see the module): a
    :class:`~surfmod.cam.roughing.Motion` from and back to the clearance height, and a
    report (``regions``, ``passes``, ``runs``, ``lifted``, ``levels``, ``contours``).
    Contours go no lower than ``bottom``."""
    out = Moves()
    info = {"regions": 0, "passes": 0, "runs": 0, "lifted": 0.0, "levels": 0, "contours": 0}
    if not mask.any():
        return out.motion(), info
    n = int(math.ceil((tool.radius + stock.cell) / stock.cell))
    di, dj = np.mgrid[-n:n + 1, -n:n + 1]
    disc = np.hypot(di, dj) * stock.cell <= tool.radius + stock.cell
    reach = ndimage.binary_dilation(mask, structure=disc)
    labels, _ = ndimage.label(reach, structure=np.ones((3, 3)))  # the regions and their (x, y) boxes
    x, y = stock.x, stock.y
    boxes = [np.array([[x[a.start], y[b.start]], [x[a.stop - 1], y[b.stop - 1]]])
             for a, b in ndimage.find_objects(labels)]
    step = tool.radius / 4
    spacing = stepover * RECUT_SHARE
    # two rasters over every box: estimated before any drop
    estimate = sum(2 * (float(np.ptp(b[:, 0])) / step + 2) * (float(np.ptp(b[:, 1])) / spacing + 2) for b in boxes)
    checks.work(estimate, max_points, "max_points", f"the rest passes over {len(boxes)} region(s)")
    top = AboveStock(stock, tool.radius, safe)
    allowed = tolerance - part.deflection + part.lift
    # the steep part first, by contours as the finishing's (its scallop, levels spaced by
    # the walls' slope): a raster climbing a wall leaves cusps as tall as its steps there
    levels_apart, _ = contour_spacing(part, tool, scallop, tolerance, stepover)
    left = _LeftNear(stock, mask, disc, labels)
    highest = ndimage.maximum(left.high, labels, np.arange(1, len(boxes) + 1))
    # the contours' work over every region, estimated before any: the waterline's fibers
    # half a radius apart, levels as close as its steepest walls put them (each region's
    # call is capped again on its own)
    closest = levels_apart * math.sin(math.radians(STEEP_ANGLE - STEEP_MARGIN))
    pairs = sum(fiber_pairs(near_box(part, tool, b), tool.radius, tool.radius / 2,
                            np.arange(h, bottom - closest, -closest), tool.corner) for b, h in zip(boxes, highest))
    if pairs > MAX_PAIRS:
        raise SurfmodError(f"scallop: the rest's contours over {len(boxes)} region(s), levels {closest:.3g} mm apart, "
                           f"need about {pairs:.3g} fiber-triangle pairs (limit {MAX_PAIRS:.0e}); choose a larger "
                           f"scallop or rest tool")
    for label, bounds in enumerate(boxes, start=1):
        left.label = label
        wl = contour_moves(out, part, tool, top, safe, STEEP_ANGLE, levels_apart, tolerance, bottom, box=bounds,
                           keep=left, highest=float(highest[label - 1]), clear=scallop + tolerance)
        info["levels"] += wl["levels"]
        info["spacing"] = levels_apart
        info["contours"] += wl["contours"]
        info["lifted"] = max(info["lifted"], wl["lifted"])
    judge_links(part, out, allowed, "rest")
    for label, bounds in enumerate(boxes, start=1):
        for direction in ("x", "y"):
            try:
                path = raster_path(part, tool, spacing, step, direction, bounds, tolerance)
            except SurfmodError as exc:
                if str(exc).startswith("bounds:"):
                    continue  # the tool touches no face there
                raise
            pts = path.points
            runs = _runs(stock.at(labels, pts, 0) == label, pts, BRIDGE_RADII * tool.radius)
            for a, b in runs:
                add_raster(out, pts[a:b], top, part, tool, safe, allowed, "a rest cut's entry")
            info["passes"] += path.n_passes
            info["runs"] += len(runs)
            info["lifted"] = max(info["lifted"], path.lifted)
        info["regions"] += 1
    return out.motion(), info


def summary_line(report: dict) -> str:
    """The rest operation's report as a line for the ``surfmod machine`` summary.

    >>> line = summary_line({"after": [0, 1], "threshold": 0.055, "runs": 3, "regions": 1, "passes": 40,
    ...                      "contours": 12, "levels": 7, "before": {"area": 12.5, "max": 1.2, "regions": 4},
    ...                      "left": {"area": 0.25, "max": 0.07, "regions": 1}})
    >>> print(line.replace(" before, ", " before,\\n").replace("; ", ";\\n"))
    rest after operations 1, 2: left more than 0.055 mm on 12.5 mm^2 (4 region(s), up to 1.2 mm) before,
    0.25 mm^2 (1 region(s), up to 0.07 mm) after;
    12 contours on 7 levels, 3 cuts in 1 region(s), 40 passes
    """
    b, a = report["before"], report["left"]
    ops = ", ".join(str(k + 1) for k in report["after"])
    return (f"rest after operations {ops}: left more than {report['threshold']:.3g} mm on {b['area']:.4g} mm^2 "
            f"({b['regions']} region(s), up to {b['max']:.3g} mm) before, {a['area']:.4g} mm^2 "
            f"({a['regions']} region(s), up to {a['max']:.3g} mm) after; "
            + (f"{report['contours']} contours on {report['levels']} levels, " if report.get("contours") else "")
            + f"{report['runs']} cuts in "
            f"{report['regions']} region(s), {report['passes']} passes"
            + (f", moves lifted by up to {report['lifted']:.3g} mm where refining could not follow the part "
               f"(material left)" if report.get("lifted", 0.0) > 0 else ""))
