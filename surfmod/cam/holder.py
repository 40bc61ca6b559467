"""Shank and holder collisions: what does not cut must clear the part and the stock.

Every move, cutting or linking, is held against the part by the verifier's own reach rule
(:func:`surfmod.cam.verify.body_stand`) and against the job's height-field stock
(:class:`surfmod.cam.rest.StockModel`).  A move that fails is left out and reported
(:class:`Held`); :func:`reach_levels` says how high a contour left out may run instead.
Probes and stock nodes are counted first (:data:`MAX_HOLDER_PROBES`,
:data:`MAX_STOCK_NODES`).  See :doc:`/guide/cam` (section "Holder and shank").
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..inputs import upright_cylinder
from .cutters import Flat
from .drop_cutter import TriangleGrid, drop
from .part_points import probes_along
from .rest import StockModel
from .roughing import PLUNGE, RAPID, Motion, Moves
from .verify import BODY_NODES, body_cell, body_stand
from .verify_kernels import sweep_body, sweep_stock

#: probes along the moves for the part check, and stock nodes of the job's model, at most
MAX_HOLDER_PROBES = 20_000_000
MAX_STOCK_NODES = BODY_NODES
#: probes along a move per disc radius
PROBES_PER_RADIUS = 16
#: cylinders OCCT's exact distance settles per operation, and the gap it must find
EXACT_CONFIRMS = 200
EXACT_GAP = 1e-7
#: contours again where the check left one out (:func:`reach_levels`): at most this many
#: levels, each this far (mm) above the lowest height the body clears
MAX_REACH_LEVELS = 16
REACH_MARGIN = 1e-4


@dataclass(frozen=True)
class Held:
    """What an operation's shank and holder kept it from: ``moves`` removed, the (x, y)
    ``area`` (mm²) where they leave more than the tolerance, the ``deepest`` point (x, y, z)
    they would have reached and the ``thickness`` left there at most."""

    moves: int
    area: float
    deepest: tuple
    thickness: float
    #: the cutting moves left out, ``(K, 2, 3)`` (start and end of each)
    cuts: np.ndarray | None = field(default=None, repr=False, compare=False)

    def __str__(self) -> str:
        x, y, z = self.deepest
        return (f"holder/shank would collide: {self.moves} moves left out, {self.area:.3g} mm² left uncut "
                f"(at most {self.thickness:.3g} mm thick), deepest ({x:.4g}, {y:.4g}, {z:.4g})")


def body_stock(stock: np.ndarray, smallest_radius: float) -> StockModel:
    """The job's stock model the bodies are held against: cells a quarter of the smallest
    tool radius, at most :data:`MAX_STOCK_NODES` nodes (coarser cells beyond)."""
    return StockModel(stock, body_cell(stock, smallest_radius), MAX_STOCK_NODES)


def _flush(triangles: np.ndarray, deflection: float, tool, points: np.ndarray, slack: float,
           skin: float) -> np.ndarray:
    """Per move (``points[k] -> points[k + 1]``): whether a disc of the tool no wider than
    its end comes within ``skin`` (the allowance the roughing left on the walls) and
    ``slack`` of a wall of the part that rises above its bottom (a finishing tool beside a
    wall; not the roughing itself, which keeps its allowance off)."""
    narrow = [h for r, h, _ in tool.body if r - slack <= tool.radius]
    flush = np.zeros(max(len(points) - 1, 0), bool)
    if not narrow or not len(flush) or skin <= 0.0:
        return flush
    probes, move, _ = probes_along(points[:-1], points[1:], tool.radius / PROBES_PER_RADIUS, MAX_HOLDER_PROBES)
    low = np.minimum(points[:-1, 2], points[1:, 2])[move]
    near = np.flatnonzero(low + min(narrow) < float(triangles[:, :, 2].max()) + deflection)
    if near.size:
        reach = tool.radius + skin + 2 * slack
        z = np.nan_to_num(drop(TriangleGrid(triangles, reach), Flat(reach), probes[near, :2]), nan=-np.inf)
        np.logical_or.at(flush, move[near], z + deflection > low[near] + min(narrow))
    return flush


def _sweep_body(stock: StockModel, a: np.ndarray, b: np.ndarray, rapid: np.ndarray, tool, slack: float,
                skip: np.ndarray, floor: np.ndarray, rise: float, flush=None, thin: float = 0.0,
                remove: bool = True):
    """``stock`` swept along the moves ``a -> b`` with the moves whose body meets it (or
    ``skip``) undone: :func:`~surfmod.cam.verify_kernels.sweep_body`'s ``(sink, removed)``
    (without ``remove``, the model is left as it is and ``sink`` measures every move).
    The model samples the stock a cell apart, coarser than the verifier's: a disc wider
    than the end is grown by a cell, so that an edge of stock between the nodes its rim
    passes is met too.  A move ``flush`` against a wall holds its discs no wider than the
    end a cell wider too, against the nodes whose stock stands no more than ``thin`` (the
    roughing's skin, often thinner than a cell, which stands between the nodes) above the
    part.  Only the stock more than ``rise`` (the cusps) above the part's top at a node
    (``floor``) counts: a grown disc comes over the wall's own column, and the cusps
    between the model's nodes are the part's rule (:func:`part_sink`)."""
    m = len(a)
    discs = np.column_stack([tool.body[:, :2], np.full(len(tool.body), np.inf)])
    wider = discs[:, 0] > tool.radius + slack
    discs[wider, 0] += stock.cell
    # beside a wall: the discs no wider than the end once more, a cell wider, against the
    # skin alone (the stock no thicker than it: not what no tool reaches in a corner)
    skin = discs[~wider].copy()
    skin[:, 0] += stock.cell
    skin[:, 2] = thin + rise
    body = np.zeros((2, 2 * len(discs), 3))
    body[0, :len(discs)] = discs
    body[1, :len(discs)] = discs
    body[1, len(discs):len(discs) + len(skin)] = skin
    of = np.zeros(m, np.int64) if flush is None else flush.astype(np.int64)
    *_, sink, _, removed = sweep_body(stock.top if remove else stock.top.copy(), float(stock.lo[0]),
                                      float(stock.lo[1]), stock.cell, np.ascontiguousarray(a),
                                      np.ascontiguousarray(b), rapid, np.full(m, tool.radius),
                                      np.full(m, tool.corner), stock.cell / 2, body, of,
                                      np.full(2, float(slack)), np.zeros(2), skip, remove, 0.0, floor, float(rise))
    return sink, removed


def part_sink(triangles: np.ndarray, deflection: float, tool, points: np.ndarray, slack: float, shape=None,
              clear: float = 0.0):
    """Per move (``points[k] -> points[k + 1]``): how far the tool's discs wider than its
    end stand below the part plus ``clear`` (the cusps) by the reach rule
    (:func:`~surfmod.cam.verify.body_stand`, see the module), -inf where they stay above.
    With ``shape``, moves flagged by the deflection alone (the mesh itself clear of the
    discs) are settled by OCCT's exact distance from each such disc as a solid cylinder
    to the part, up to :data:`EXACT_CONFIRMS` cylinders (beyond, they stay flagged)."""
    sink = np.full(max(len(points) - 1, 0), -np.inf)
    discs = [(r, h, length) for r, h, length in tool.body if r - slack > tool.radius]
    if not discs or not len(sink):
        return sink
    top = float(triangles[:, :, 2].max()) + deflection
    spacing = min(r for r, _, _ in discs) / PROBES_PER_RADIUS
    probes, move, spacing = probes_along(points[:-1], points[1:], spacing, MAX_HOLDER_PROBES)
    seg = points[1:] - points[:-1]
    slope = np.abs(seg[:, 2]) / np.maximum(np.linalg.norm(seg, axis=1), 1e-300)
    # the lowest the move goes within half a spacing
    low = np.maximum(probes[:, 2] - slope[move] * spacing / 2, np.minimum(points[:-1, 2], points[1:, 2])[move])

    def mesh(xy, r):
        return np.nan_to_num(drop(TriangleGrid(triangles, r), Flat(r), xy), nan=-np.inf) + deflection

    depth = body_stand(mesh, probes[:, :2], tool, slack, spacing / 2, clear, low, top) - low
    np.maximum.at(sink, move, depth.max(axis=0))
    hit = depth > 0.0
    if shape is None or not hit.any():
        return sink
    disc, which = np.nonzero(hit)
    # a move flagged only by the deflection is confirmed exactly when all its flagged
    # probes are few enough
    close = sink[move[which]] <= deflection
    if not close.any() or close.sum() > EXACT_CONFIRMS:
        return sink
    which, disc = which[close], disc[close]
    radius = np.array([discs[q][0] - slack + spacing / 2 for q in disc])
    base = np.column_stack([probes[which, :2], low[which] + np.array([discs[q][1] for q in disc]) - clear])
    gap = _cylinder_clearance(shape, base, radius, [max(discs[q][2], 1e-6) for q in disc]) > EXACT_GAP
    cleared = np.ones(len(sink), bool)
    np.logical_and.at(cleared, move[which], gap)
    settled = np.unique(move[which])
    sink[settled[cleared[settled]]] = -np.inf
    return sink


def _cylinder_clearance(shape, bases, radii, heights) -> np.ndarray:
    """The distance of each upright solid cylinder (``bases`` (N, 3) the centres of their
    bottoms, ``radii``, ``heights``) from ``shape`` (OCCT's ``BRepExtrema``): 0 where they
    touch or overlap, or where one lies inside the other."""
    from ..occ.booleans import min_distance
    from ..occ.topo import wrapped

    target = wrapped(shape)
    out = np.empty(len(bases))
    for k, (p, r, h) in enumerate(zip(bases, radii, heights)):
        d, _, _, inner = min_distance(wrapped(upright_cylinder(p, r, h)), target)
        out[k] = 0.0 if inner else d
    return out


def relink(motion: Motion, removed: np.ndarray, safe: float) -> Motion:
    """``motion`` without the moves ``removed`` (per move into ``points[k + 1]``): after a
    gap the tool goes up to ``safe``, across, and down onto the start of the next cutting
    move kept; the program's own links in the gap are dropped."""
    pts, kind = motion.points, motion.kind
    out = Moves()
    out.add(pts[:1], kind[0])
    gap = False
    for k in range(1, len(pts)):
        if removed[k - 1]:
            gap = True
            continue
        if gap and kind[k] == RAPID:
            continue
        if gap:
            start, cur = pts[k - 1], out.last
            if np.any(start != cur):
                if cur[2] < safe:
                    out.add([[cur[0], cur[1], safe]], RAPID)
                out.add([[start[0], start[1], safe]], RAPID)
                # at the feed: the moves left out leave stock the program's own entries
                # did not expect
                out.add([start], PLUNGE)
            gap = False
        out.add(pts[k:k + 1], kind[k])
    last = out.last
    if gap and last[2] < safe:
        out.add([[last[0], last[1], safe]], RAPID)
    return _without_dips(out.motion())


def _without_dips(motion: Motion) -> Motion:
    """``motion`` without the rapid dips a removal leaves: a rapid straight down whose
    next move is a rapid straight back up (the program's own entry to moves left out).

    >>> m = _without_dips(Motion(np.array([[0, 0, 9], [0, 0, 1], [0, 0, 9], [5, 0, 9.0]]), np.full(4, RAPID, np.int8)))
    >>> m.points.tolist()
    [[0.0, 0.0, 9.0], [5.0, 0.0, 9.0]]
    """
    p, kind = motion.points, motion.kind
    if len(p) < 3:
        return motion
    a, b, c = p[:-2], p[1:-1], p[2:]
    dip = ((kind[1:-1] == RAPID) & (kind[2:] == RAPID) & np.all(a[:, :2] == b[:, :2], axis=1)
           & np.all(b[:, :2] == c[:, :2], axis=1) & (b[:, 2] < a[:, 2]) & (c[:, 2] > b[:, 2]))
    if not dip.any():
        return motion
    keep = np.r_[True, ~dip, True]
    keep[2:] &= ~(dip & np.all(c == a, axis=1))  # back where it was: the climb goes too
    return Motion(p[keep], kind[keep])


def clear_body(motion: Motion, tool, stock: StockModel, triangles: np.ndarray, deflection: float, slack: float,
               safe: float, shape=None, cusp: float = 0.0, skin: float = 0.0, floor: np.ndarray | None = None):
    """``(motion, held)``: ``motion`` swept through ``stock`` with the moves whose shank or
    holder would come within ``cusp`` of the part (``triangles``, and ``shape`` for the
    close calls; the highest cusp the passes so far leave) or meet the stock left on it
    (``skin`` the roughing's allowance on the walls) removed and relinked
    (:func:`relink`), and what that leaves (:func:`left_out`).  ``floor``: the part's top
    over the model's nodes (:meth:`~surfmod.cam.rest.StockModel.part_top`), when the caller
    has it."""
    pts = np.asarray(motion.points, float)
    if len(pts) < 2:
        return motion, None
    rapid = motion.kind[1:] == RAPID
    skip = part_sink(triangles, deflection, tool, pts, slack, shape, cusp) > 0.0
    flush = _flush(triangles, deflection, tool, pts, slack, skin)
    floor = stock.part_top(triangles) if floor is None else floor
    _, removed = _sweep_body(stock, pts[:-1], pts[1:], rapid, tool, slack, skip, floor, cusp + slack, flush, skin)
    if not removed.any():
        return motion, None
    cuts = removed & ~rapid  # links replaced by the relinking leave nothing
    return relink(motion, removed, safe), left_out(stock, tool, pts[:-1][cuts], pts[1:][cuts], int(removed.sum()),
                                                   slack)


def left_out(stock: StockModel, tool, a: np.ndarray, b: np.ndarray, moves: int, slack: float) -> Held | None:
    """What the cutting moves ``a -> b`` left out (of ``moves`` removed in all) would have
    taken beyond the stock as the model holds it now (None where no more than ``slack``);
    the sweep is a minimum, so this may be asked again after more moves are swept."""
    if not len(a):
        return None
    would = stock.top.copy()
    n = len(a)
    sweep_stock(would, float(stock.lo[0]), float(stock.lo[1]), stock.cell, np.ascontiguousarray(a),
                np.ascontiguousarray(b), np.zeros(n, np.bool_), np.full(n, tool.radius), np.full(n, tool.corner),
                stock.cell / 2)
    left = stock.top - would
    over = left > slack
    if not over.any():  # the moves left out would have taken no more than the tolerance
        return None
    i, j = np.unravel_index(int(np.argmin(np.where(over, would, np.inf))), would.shape)
    deepest = (float(stock.x[i]), float(stock.y[j]), float(would[i, j]))
    return Held(moves, float(over.sum()) * stock.cell ** 2, deepest, float(left[over].max()),
                np.stack([a, b], axis=1))


def reach_levels(held: Held, tool, stock: StockModel, triangles: np.ndarray, deflection: float, slack: float,
                 cusp: float, window: float, skin: float, floor: np.ndarray) -> list:
    """Where the check left out moves at constant height (a waterline contour's), the
    lowest heights the tool can cut there: each move raised by how far the stock model
    (by ``cusp`` too) or the part stands above its discs' bottoms, the moves grouped by
    that height, a group at most ``window`` deep (else the window doubles until at most
    :data:`MAX_REACH_LEVELS` groups are left) and cut at its highest (``floor``: as
    :func:`clear_body`'s).  Returns ``(z, moves)`` pairs, lowest first, ``moves`` the
    group's ``(K, 2, 3)`` moves as left out."""
    if held is None or held.cuts is None:
        return []
    cuts = held.cuts[np.abs(held.cuts[:, 0, 2] - held.cuts[:, 1, 2]) <= 1e-9]
    if not len(cuts):
        return []
    a, b = cuts[:, 0], cuts[:, 1]
    # each move alone (the polyline a0 b0 a1 b1 ...: its even moves)
    flush = _flush(triangles, deflection, tool, cuts.reshape(-1, 3), slack, skin)[::2]
    sink, _ = _sweep_body(stock, a, b, np.zeros(len(a), np.bool_), tool, slack, np.zeros(len(a), np.bool_),
                          floor, cusp + slack, flush, skin, remove=False)
    part = part_sink(triangles, deflection, tool, cuts.reshape(-1, 3), slack, clear=cusp)[::2]
    up = np.maximum(sink, part)
    z = a[:, 2] + up + REACH_MARGIN
    ok = np.isfinite(up) & (up > 0.0)
    z, cuts = z[ok], cuts[ok]
    order = np.argsort(z)
    z, cuts = z[order], cuts[order]
    while True:
        groups, start = [], 0
        while start < len(z):
            end = int(np.searchsorted(z, z[start] + window, "right"))
            groups.append((float(z[end - 1]), cuts[start:end]))
            start = end
        if len(groups) <= MAX_REACH_LEVELS:
            return groups
        window *= 2.0
