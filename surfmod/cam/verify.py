"""Every program judged before it leaves (:func:`verify_job`, :func:`verify_toolpath`): the
G-code read back, swept through a stock model and held against the exact part.

The judge shares nothing with how the moves were made: the program is read from its text
(:mod:`surfmod.cam.program`), the part is points on its exact faces and edges
(:mod:`surfmod.cam.part_points`), the walls are dexels (:mod:`surfmod.cam.wall_dexels`).
The reach rule of shank and holder (:func:`body_stand`) is the one the job keeps, so the
judge asks nothing of a tool the job did not.  Work is estimated first; past a cap the
judge samples more coarsely and says so, never refuses.
See :doc:`/guide/cam` (section "Every program verified before it leaves").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from ..errors import SurfmodError
from ..inputs import to_shape
from . import verify_kernels as K
from . import wall_dexels as W
from .part_points import MAX_PROBES, MAX_SAMPLES, PartPoints, bucket_cell, coarser_note, probe_spacing, \
    probes_along, sampled_part, spacing_for
from .program import ProgramMoves, concatenate, read_program
from .stock_field import KEPT_NODES, StockField, grid_axes, grid_points

#: stock nodes one verification may take (its points on the part and probes along the moves:
#: ``part_points.MAX_SAMPLES``, ``MAX_PROBES``)
#: probes of the holder and shank check along the moves (a radius of the narrowest disc
#: wider than the end over 16 apart: few beside the gouge probes), at most
MAX_BODY_PROBES = 20_000_000
MAX_NODES = 30_000_000
#: interval cuts the dexels along x and y may take (:func:`~surfmod.cam.wall_dexels.sweep_work`)
MAX_DEXEL_WORK = 400_000_000
#: dexels along x and y together, at most (each holds ``wall_dexels.SEGMENTS`` intervals: 256 MB)
MAX_DEXELS = 2_000_000
#: stock points on walls the dexels judge, at most (beyond it every n-th is judged)
MAX_WALL_POINTS = 1_000_000
#: stock points on walls asked at a time whether the finishing tool reaches them
REACH_CHUNK = 4096
#: stock nodes of the model the job holds shanks and holders against, at most
#: (:func:`body_cell`, :func:`surfmod.cam.holder.body_stock`)
BODY_NODES = 4_000_000
#: the stock kept at most this many times along a sweep of the program, in at most this
#: many bytes (:func:`_sweep`)
SWEEP_MARKS = 8
SWEEP_BYTES = 64_000_000
#: nodes of the stock steeper than this (degrees) are walls the height field cannot judge
WALL_SLOPE = 80.0
#: how many of the deepest ball probes OCCT's exact distance measures again
EXACT_PROBES = 16
#: rounds of them on walls, where the exact foot may leave a point unjudged (an overhang)
EXACT_ROUNDS = 8


@dataclass(frozen=True)
class Finding:
    """One promise measured: ``worst`` (mm) against ``limit``, ``where`` the worst is
    (x, y, z), ``count`` moves or nodes beyond the limit, ``line`` the program line of the
    worst move (0: none)."""

    what: str
    worst: float
    limit: float
    where: tuple | None = None
    count: int = 0
    line: int = 0
    #: the (x, y) boxes ``(x0, y0, x1, y1)`` of the connected regions beyond the limit
    boxes: tuple = ()
    #: the moves beyond the limit as ``(operation, start, end)`` (rapids through stock:
    #: what :func:`surfmod.cam.job.machine` re-links)
    segments: tuple = ()

    @property
    def ok(self) -> bool:
        return not self.worst > self.limit

    def __str__(self) -> str:
        at = "" if self.where is None else " at ({:.4g}, {:.4g}, {:.4g})".format(*self.where)
        line = f" (line {self.line})" if self.line else ""
        if self.worst > 0:
            worst = f"max {self.worst:.3g} mm"
        elif self.what.startswith("residual"):  # material left, not points inside a tool
            worst = "nothing left" if np.isfinite(self.worst) else "no place the tool reaches"
        else:
            worst = "nothing inside the tool"
        verdict = "ok" if self.ok else f"BROKEN: {self.count} beyond it"
        return f"{self.what}: {worst}{at}{line}, limit {self.limit:.3g} mm, {verdict}"


@dataclass(frozen=True)
class Verification:
    """What :func:`verify_job` / :func:`verify_toolpath` found: the ``findings`` (gouge per
    operation, rapids, residual, residual on walls), and the work: points on the part, probes
    along the moves, stock nodes, the wall nodes the height field leaves to the dexels, the
    dexels kept and the points of their stock judged."""

    findings: tuple
    samples: int
    probes: int
    nodes: int = 0
    walls: int = 0
    spacing: float = 0.0
    notes: tuple = field(default=())
    #: probes of the holder and shank check (their own cap, ``MAX_BODY_PROBES``)
    body_probes: int = 0
    #: the dexels along x and y that judged the walls, and the points of their stock judged
    dexels: int = 0
    wall_points: int = 0
    #: the stock after the program (:class:`~surfmod.cam.stock_field.StockField`, at most
    #: ``KEPT_NODES`` nodes; None for a tool path alone)
    stock: StockField | None = field(default=None, repr=False, compare=False)
    #: what was measured against the part alone, for a verdict after a repair
    #: (:func:`verify_job`'s ``before``)
    measured: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def ok(self) -> bool:
        return all(f.ok for f in self.findings)

    def lines(self) -> list[str]:
        head = (f"verified against the exact part: {self.samples:,} points {self.spacing:.3g} mm apart, "
                f"{self.probes:,} probes along the moves"
                + (f" ({self.body_probes:,} more for holder and shank)" if self.body_probes else "")
                + (f", stock of {self.nodes:,} nodes ({self.walls:,} on walls" if self.nodes else "")
                + (f", judged by {self.dexels:,} dexels along x and y at {self.wall_points:,} points)"
                   if self.nodes and self.dexels else ")" if self.nodes else ""))
        return [head] + [str(f) for f in self.findings] + list(self.notes)

    def __str__(self) -> str:
        return "\n".join(self.lines())


@dataclass(frozen=True)
class _Measured:
    """One check's measure of each move against the part alone (no stock: the same
    wherever the move stands in the program): the moves, the probes' spacing, and per move
    the deepest ``depth``, ``where`` it is and how many ``probes`` it took."""

    start: np.ndarray
    end: np.ndarray
    used: float
    depth: np.ndarray
    where: np.ndarray
    probes: np.ndarray


def _per_move(start: np.ndarray, end: np.ndarray, spacing: float, max_probes: int, measure, before):
    """:class:`_Measured` of the moves ``start``-``end``: ``measure(probes, move, used)``
    gives each probe's depth and where; the moves at the head and the tail that
    ``before`` (a :class:`_Measured` at the same spacing, or None) measured already are
    taken from it, so a verdict after a repair that changed one stretch of the program
    measures that stretch alone."""
    used = probe_spacing(start, end, spacing, max_probes)
    m = len(start)
    head = tail = 0
    if before is not None and before.used == used:
        n = min(m, len(before.start))
        same = np.all((start[:n] == before.start[:n]) & (end[:n] == before.end[:n]), axis=1)
        head = int(np.argmin(same)) if not same.all() else n
        k = n - head
        same = np.all((start[m - k:] == before.start[len(before.start) - k:])
                      & (end[m - k:] == before.end[len(before.end) - k:]), axis=1)[::-1]
        tail = int(np.argmin(same)) if not same.all() else k
    depth, where, probes = np.empty(m), np.empty((m, 3)), np.empty(m, np.int64)
    if head or tail:
        old = len(before.start)
        for mine, theirs in ((slice(0, head), slice(0, head)), (slice(m - tail, m), slice(old - tail, old))):
            depth[mine], where[mine], probes[mine] = before.depth[theirs], before.where[theirs], before.probes[theirs]
    fresh = slice(head, m - tail)
    if m - tail > head:
        pts, move, _ = probes_along(start[fresh], end[fresh], used, max_probes)
        d, w = measure(pts, move + head, used)
        order = np.lexsort((d, move))  # each move's deepest probe: the last of its group
        last = order[np.r_[move[order][1:] != move[order][:-1], True]]
        depth[fresh], where[fresh] = d[last], w[last]
        probes[fresh] = np.bincount(move, minlength=m - tail - head)
    return _Measured(start, end, used, depth, where, probes)


def _gouge(part: PartPoints, moves: ProgramMoves, pick: np.ndarray, radius: float, corner: float, limit: float,
           spacing: float, what: str, max_probes: int, notes: list, exact_shape=None, before=None):
    """The deepest any point of the part comes into the tool along the picked moves, and
    its :class:`_Measured` (``before``: the same check's before a repair, see
    :func:`_per_move`); a note joins ``notes`` when the probes had to stand farther apart
    than ``spacing``."""
    if not pick.any():
        return Finding(what, -np.inf, limit), 0, None
    idx = np.flatnonzero(pick)

    def measure(probes, move, used):
        depth, which = part.deepest(probes, radius, corner)
        if exact_shape is not None and corner == radius and depth.max() > 0:
            # the deepest ball probes measured by OCCT's exact distance from the centre to
            # the faces (a loose vertex or wire of the file is construction geometry, not
            # material); those of the moves a verdict before measured are its deepest too
            from ..occ.topo import closest_on_face, compound, faces_of

            top = np.argsort(depth)[-EXACT_PROBES:]
            top = top[depth[top] > 0]
            dist, _ = closest_on_face(compound(faces_of(exact_shape)), probes[top] + [0.0, 0.0, radius])
            depth[top] = np.maximum(depth[top], radius - dist)
        return depth, np.where((which >= 0)[:, None], part.points[np.maximum(which, 0)], probes)

    got = _per_move(moves.start[idx], moves.end[idx], spacing, max_probes, measure, before)
    if got.used > spacing:
        notes.append(f"note: {what}: probes {got.used:.3g} mm apart along the moves, coarser than the {spacing:.3g} "
                     f"asked ({max_probes:,} at most): between them a tool may come nearer the part than measured")
    n = int(got.probes.sum())
    k = int(np.argmax(got.depth))
    if got.depth[k] <= 0:
        return Finding(what, float(got.depth[k]), limit), n, got
    return Finding(what, float(got.depth[k]), limit, tuple(float(v) for v in got.where[k]),
                   int((got.depth > limit).sum()), int(moves.line[idx[k]])), n, got


def _body_part(part: PartPoints, moves: ProgramMoves, pick: np.ndarray, tool, slack: float, limit: float,
               max_probes: int, what: str, before=None):
    """How far the part's points stand above the bottom of the tool's discs wider than its
    end (:attr:`~surfmod.cam.tool.Tool.body`, each less ``slack``, grown by half the probes'
    spacing, at the lowest height within it) along the picked moves, against ``limit``, and
    its :class:`_Measured` (``before``: see :func:`_per_move`)."""
    discs = [(r, h) for r, h, _ in tool.body if r - slack > tool.radius]
    if not discs or not pick.any():
        return Finding(what, -np.inf, limit), 0, None
    idx = np.flatnonzero(pick)
    a, b = moves.start[idx], moves.end[idx]
    ceiling = float(part.points[:, 2].max())

    def measure(probes, move, used):
        seg = b[move] - a[move]
        low = np.maximum(probes[:, 2] - np.abs(seg[:, 2]) / np.maximum(np.linalg.norm(seg, axis=1), 1e-300)
                         * used / 2, np.minimum(a[move, 2], b[move, 2]))
        depth = np.full(len(probes), -np.inf)
        for r, h in discs:
            near = low + h < ceiling
            if near.any():
                depth[near] = np.maximum(depth[near],
                                         part.drop(probes[near, :2], r - slack + used / 2, 0.0) - (low[near] + h))
        return depth, probes

    got = _per_move(a, b, min(r for r, _ in discs) / 16, max_probes, measure, before)
    n = int(got.probes.sum())
    k = int(np.argmax(got.depth))
    if not got.depth[k] > 0:
        return Finding(what, float(got.depth[k]), limit), n, got
    return Finding(what, float(got.depth[k]), limit, tuple(float(v) for v in got.where[k]),
                   int((got.depth > limit).sum()), int(moves.line[idx[k]])), n, got


# -- the job --------------------------------------------------------------------------------
def _program_moves(job, texts: list[str], post: str) -> tuple[ProgramMoves, np.ndarray]:
    """The programs' moves in the order the machine runs them, and each move's operation."""
    if post == "linuxcnc":
        groups = [(texts[0], list(range(len(job.operations))), 0)]
    else:
        numbers = list(dict.fromkeys(op.tool.number for op in job.operations))
        if len(numbers) != len(texts):
            raise SurfmodError(f"programs: expected {len(numbers)} GRBL programs (one per tool), got {len(texts)}")
        groups = [(text, [k for k, op in enumerate(job.operations) if op.tool.number == n], n)
                  for text, n in zip(texts, numbers)]
    parts, owners = [], []
    for text, ops, tool in groups:
        moves = read_program(text, tool=tool)
        # the posts open each operation with its comment: count them along the text
        marks = [i for i, line in enumerate(text.splitlines(), start=1) if line.startswith("(operation:")]
        if len(marks) != len(ops):
            raise SurfmodError(f"programs: {len(marks)} operations in the text, the job has {len(ops)}")
        local = np.searchsorted(np.array(marks), moves.line, side="right") - 1
        if np.any(local < 0):
            raise SurfmodError("programs: a move before the first operation")
        parts.append(moves)
        owners.append(np.asarray(ops)[local])
    return concatenate(parts), np.concatenate(owners)


def _sweep(top, lo, cell, moves: ProgramMoves, owner, radii, corners, discs, slack, kept):
    """:func:`~surfmod.cam.verify_kernels.sweep_body` over the moves (its per-move
    ``into``, node, ``sink``, node) in stretches, the stock ``top`` kept as it stands at
    the start of each; ``kept``: what the sweep of the verdict before kept.  The moves
    before the first one that differs from that verdict's meet the same stock, so their
    stretches are taken from it and the sweep goes on from the last kept stock before
    that move (a re-cut appends its passes: the whole program is not swept again).
    Cutting a sweep into stretches changes no finding: the stock carries over, and the
    kernel's block maxima only skip nodes that could not count."""
    columns = (moves.start, moves.end, moves.rapid, owner, radii, corners)
    m = len(owner)
    marks = min(SWEEP_MARKS, SWEEP_BYTES // top.nbytes)  # none: a stock too large to keep is swept whole
    stride = kept["stride"] if kept else max(-(-m // max(marks, 1)), 1)
    out = [np.full(m, -np.inf), np.full(m, -1, np.int64), np.full(m, -np.inf), np.full(m, -1, np.int64)]
    begin, tops = 0, {}
    if kept and kept["tops"]:
        n = min(m, len(kept["columns"][0]))
        differ = np.zeros(n, bool)
        for a, b in zip(columns, kept["columns"]):
            d = a[:n] != b[:n]
            differ |= d if d.ndim == 1 else d.any(axis=1)
        first = int(np.argmax(differ)) if differ.any() else n
        begin = max(k for k in kept["tops"] if k <= first)
        top[:] = kept["tops"][begin]
        tops = {k: v for k, v in kept["tops"].items() if k <= begin}
        for mine, theirs in zip(out, kept["out"]):
            mine[:begin] = theirs[:begin]
    for a in range(begin, max(m, 1), stride):
        b = min(a + stride, m)
        if marks:
            tops[a] = top.copy()
        got = K.sweep_body(top, float(lo[0]), float(lo[1]), cell, moves.start[a:b], moves.end[a:b], moves.rapid[a:b],
                           radii[a:b], corners[a:b], cell / 2, discs, np.ascontiguousarray(owner[a:b], dtype=np.int64),
                           slack, np.zeros(len(slack)), np.zeros(b - a, np.bool_), False, cell, np.zeros((1, 1)), 0.0)
        for mine, part in zip(out, got):
            mine[a:b] = part
    return out, {"stride": stride, "columns": columns, "tops": tops, "out": out}


def verify_job(job, post: str = "linuxcnc", texts: list[str] | None = None, *, max_samples: int = MAX_SAMPLES,
               max_probes: int = MAX_PROBES, max_nodes: int = MAX_NODES,
               max_dexel_work: int = MAX_DEXEL_WORK, before: Verification | None = None) -> Verification:
    """Judge the program(s) of ``job`` (as :func:`surfmod.cam.post.programs` writes them
    for ``post``, or the given ``texts``) against the exact part and the stock: gouge per
    operation, rapids through stock or part, the scallop left (see the module).

    ``before``: the verdict of this job before a repair changed a stretch of its program
    (:func:`surfmod.cam.job.machine`'s re-cut and re-link).  What is measured against the
    part alone, move by move (gouge, rapids into the part, holder and shank over the
    part), is taken from it for the moves before and after that stretch, as are the
    part's heights under the stock's nodes and what the finishing tool reaches there; the
    stock is swept again from the last state kept before the first changed move (what a move
    meets depends on every move before it).

    >>> import surfmod as sm, build123d as bd
    >>> job = sm.machine(bd.Box(20, 20, 5), 1.0, [sm.Rough(sm.Tool("flat", 3.0), allowance=0.3),
    ...                                          sm.Finish(sm.Tool("ball", 2.0), scallop=0.05)], verify=False)
    >>> v = verify_job(job)
    >>> v.ok, [f.what.split(" (")[0] for f in v.findings]
    (True, ['gouge, roughing', 'gouge, finishing', 'rapids', 'holder and shank, roughing', 'holder and shank, finishing', 'residual after finishing', 'residual on walls after finishing'])
    """
    from .post import programs

    texts = programs(job, post) if texts is None else list(texts)
    moves, owner = _program_moves(job, texts, post)
    digits = 1e-4  # the posts' 4 decimals: x and y rounded to the nearest, z up
    plans = []
    for k, op in enumerate(job.operations):
        tool = op.tool
        # roughing keeps its allowance: judged with the tool grown by it
        a = float(op.report.get("allowance", 0.0)) if op.name == "roughing" else 0.0
        cutter = tool.cutter.grown(a) if a > 0 else tool.cutter
        plans.append((k, op, cutter, float(op.report["tolerance"]) + digits))
    spacing = min(spacing_for(limit / 2, c.radius, c.corner) for _, _, c, limit in plans)
    sag = min(limit for _, _, _, limit in plans) / 4
    asked = spacing
    part, spacing = sampled_part(job.part, spacing, bucket_cell(spacing, min(c.radius for _, _, c, _ in plans)),
                                 max_samples, sag, fit=True)
    notes = coarser_note(spacing, asked, max_samples)
    # what a verdict before measured on this same sampling of the part: the part and how
    # it was sampled, not its points (17 million on NIST CTC 02, kept by sampled_part alone)
    sampling = (job.part, spacing, part.cell, len(part.points))
    kept = before.measured.get("sampling") if before is not None else None
    same = kept is not None and kept[0] is job.part and kept[1:] == sampling[1:]
    old = before.measured if same else {}
    measured = {"sampling": sampling}
    # the probes along the moves, shared out by the number of moves each check judges
    cuts = [(owner == k) & ~moves.rapid for k, _, _, _ in plans]
    rapids = [(owner == k) & moves.rapid for k, _, _, _ in plans]
    judged = max(sum(int(p.sum()) for p in cuts + rapids), 1)

    def share(pick):
        return max(max_probes * int(pick.sum()) // judged, 1)

    findings, probes = [], 0
    for (k, op, cutter, limit), pick in zip(plans, cuts):
        key = ("gouge", k, cutter.radius, cutter.corner, limit)
        found, n, measured[key] = _gouge(part, moves, pick, cutter.radius, cutter.corner, limit, spacing,
                                         f"gouge, {op.name} (tool {op.tool.number})", share(pick), notes, job.part,
                                         old.get(key))
        findings.append(found)
        probes += n
    # rapids: no point of the part inside the tool, and (below) no stock under it
    rapid_part = Finding("rapids", -np.inf, 0.0)
    for (k, op, _, _), pick in zip(plans, rapids):
        key = ("rapids", k, op.tool.radius, op.tool.corner)
        found, n, measured[key] = _gouge(part, moves, pick, op.tool.radius, op.tool.corner, 0.0, spacing, "rapids",
                                         share(pick), notes, before=old.get(key))
        probes += n
        if found.worst > rapid_part.worst:
            rapid_part = found
    # the residual is judged after the last finishing or rest operation, with its tool
    finishing = [p for p in plans if p[1].name in ("finishing", "rest")]
    stepover = min((float(p[1].report.get("stepover") or p[1].tool.radius) for p in finishing),
                   default=min(op.tool.radius for op in job.operations))
    lo, hi = np.asarray(job.stock, float)
    cell, nx, ny, note = stock_cells(job.stock, max(stepover / 4, 1e-3), max_nodes)
    notes += [note] if note else []
    top = np.full((nx, ny), float(hi[2]))
    radii = np.array([op.tool.radius for op in job.operations], float)[owner]
    corners = np.array([op.tool.corner for op in job.operations], float)[owner]
    # the shank and holder of each move's tool measured against the stock as it stands then
    bodies = [op.tool.body for op in job.operations]
    discs = np.zeros((len(bodies), max(len(b) for b in bodies), 2))
    for k, b in enumerate(bodies):
        discs[k, :len(b)] = b[:, :2]
    slack = np.array([limit for _, _, _, limit in plans])
    # a disc may rub sideways within the operation's limit, never stand below the part or
    # the stock: beyond the 4 decimals and the stamped sweep's sag over a quarter cell
    low_limit = digits + (cell / 4) ** 2 / (2 * cell)
    key = ("sweep", tuple(lo), cell, nx, ny, discs.tobytes(), slack.tobytes())
    (into, node, sink, sink_node), measured[key] = _sweep(top, lo, cell, moves, owner, radii, corners, discs, slack,
                                                          old.get(key))
    held, body_probes = [], 0
    for k, op, _, limit in plans:
        key = ("body", k, op.tool.radius, op.tool.body.tobytes(), limit)
        found, n, measured[key] = _body_part(part, moves, owner == k, op.tool, limit, low_limit,
                                             max(MAX_BODY_PROBES * int((owner == k).sum()) // max(len(owner), 1), 1),
                                             f"holder and shank, {op.name} (tool {op.tool.number})", old.get(key))
        body_probes += n
        mine = np.flatnonzero(owner == k)
        if mine.size and sink[mine].max() > max(found.worst, 0.0):
            w = mine[int(np.argmax(sink[mine]))]
            i, j = divmod(int(sink_node[w]), ny)
            found = Finding(found.what, float(sink[w]), low_limit,
                            (float(lo[0] + i * cell), float(lo[1] + j * cell), float(top[i, j])),
                            int((sink[mine] > low_limit).sum()), int(moves.line[w]))
        held.append(found)
    through = np.where(moves.rapid, into, -np.inf)
    stock_hit = 1e-6  # a rapid grazing the top it just cut is no collision
    k = int(np.argmax(through)) if len(through) else 0
    if len(through) and through[k] > stock_hit:
        i, j = divmod(int(node[k]), ny)
        where = (float(lo[0] + i * cell), float(lo[1] + j * cell), float(top[i, j]))
        hits = np.flatnonzero(through > stock_hit)
        segments = tuple((int(owner[h]), tuple(map(float, moves.start[h])), tuple(map(float, moves.end[h])))
                         for h in hits)
        stock = Finding("rapids", float(through[k]), 0.0, where, hits.size, int(moves.line[k]), segments=segments)
    else:
        stock = Finding("rapids", -np.inf, 0.0)
    findings.append(replace(max(stock, rapid_part, key=lambda f: f.worst), segments=stock.segments))
    findings += held
    uncut = ~moves.rapid & ~moves.spindle & (np.linalg.norm(moves.end - moves.start, axis=1) > 0)
    if uncut.any():
        findings.append(Finding("cuts with the spindle stopped", float(uncut.sum()), 0.0, None, int(uncut.sum()),
                                int(moves.line[np.argmax(uncut)])))
    walls = dexels = judged_walls = 0
    # the part under each node: the highest of its points within the node's cell
    key = ("under", tuple(lo), cell, nx, ny)
    under = measured[key] = old.get(key, None)
    if under is None:
        under = measured[key] = part.drop(grid_points(lo[:2], cell, (nx, ny)), 0.75 * cell, 0.0).reshape(nx, ny)
    if finishing:
        k, op, cutter, limit = finishing[-1]
        # the discs as wide and as high as the job holds them (its stock model's cell, the cusps)
        grow = body_cell(job.stock, min(o.tool.radius for o in job.operations))
        clear = cusp_clearance(job.operations[:k + 1])
        key = ("reach", k, tuple(lo), cell, nx, ny, cutter.radius, cutter.corner, op.tool.body.tobytes(), limit, grow,
               clear)
        measured[key] = old.get(key) or _reach(part, lo, cell, (nx, ny), op, cutter, limit, grow, clear)
        reach, held = measured[key]
        found, walls, held = _residual(top, under, reach, held, lo, cell, op, cutter, limit)
        findings.append(found)
        if held:
            notes.append(f"note: residual: {held:,} nodes the shank or holder keeps the {op.name} tool from, "
                         f"not judged (the holder finding and the operation's report say what is left)")
        found, dexels, judged_walls = _wall_residual(part, moves, radii, corners, np.asarray(job.stock, float), under,
                                                     cell, op, cutter, limit, max_dexel_work, notes, job.part, grow,
                                                     clear)
        findings.append(found)
    kept = StockField.over_part(top, under, lo[:2], cell, WALL_SLOPE, KEPT_NODES)
    return Verification(tuple(findings), len(part.points), probes, nx * ny, walls, spacing, tuple(notes),
                        stock=kept, body_probes=body_probes, dexels=dexels, wall_points=judged_walls,
                        measured=measured)


def body_cell(stock, smallest_radius: float) -> float:
    """The cell of the stock model a job holds its shanks and holders against: a quarter
    of its smallest tool radius, coarser beyond :data:`BODY_NODES` nodes.  The job grows
    each disc wider than the end by it (:func:`surfmod.cam.holder.body_stock`), and the
    walls' judge asks where the tool reaches with the same discs."""
    return stock_cells(stock, smallest_radius / 4, BODY_NODES)[0]


def stock_cells(stock, cell: float, max_nodes: int = MAX_NODES):
    """The height-field stock's grid over the box ``stock``: ``(cell, nx, ny, note)``,
    nodes ``lo + cell * (i, j)``; where ``cell`` would give more than ``max_nodes`` nodes
    the cells are coarser and ``note`` says so (else None).

    >>> stock_cells([[0, 0, 0], [10, 5, 2]], 0.5)[1:]
    (21, 11, None)
    """
    lo, hi = np.asarray(stock, float)
    nx, ny = (int(math.floor((hi[i] - lo[i]) / cell)) + 1 for i in range(2))
    if nx * ny <= max_nodes:
        return cell, nx, ny, None
    wanted, cell = cell, cell * 1.05 * math.sqrt(nx * ny / max_nodes)
    nx, ny = (int(math.floor((hi[i] - lo[i]) / cell)) + 1 for i in range(2))
    return cell, nx, ny, (f"note: stock cells {cell:.3g} mm, coarser than the {wanted:.3g} the stepover asks "
                          f"({max_nodes:,} nodes at most): cusps narrower than a cell are seen lower than they are")


def _reach(part: PartPoints, lo: np.ndarray, cell: float, shape: tuple, op, cutter, limit: float, grow: float,
           clear: float):
    """``(reach, held)`` on the stock's nodes: the lowest the finishing tool's lower
    surface reaches over each (the part's closing by the tool), and the nodes the shank or
    holder keeps it from (:func:`body_stand`, its discs ``grow`` wider and ``clear`` above
    the part; see :func:`_residual`)."""
    nx, ny = shape
    xy = grid_points(lo[:2], cell, shape)
    tips = part.drop(xy, cutter.radius, cutter.corner).reshape(nx, ny)
    reach = K.closing(tips, cell, cutter.radius, cutter.corner)
    # where the shank or holder stops the tool above the part, the tool does not reach it:
    # the lowest the whole tool reaches, by the reach rule the job follows
    body = body_stand(lambda q, r: part.drop(q, r, 0.0), xy, op.tool, limit, grow, clear)
    held = np.zeros((nx, ny), bool)
    if len(body):
        stand = np.maximum(tips, body.max(axis=0).reshape(nx, ny))
        held = K.closing(stand, cell, cutter.radius, cutter.corner) > reach + limit
        # the job leaves out whole moves, judged with some caution: a tool's footprint
        # round what the holder keeps it from is not judged either
        n = int(cutter.radius / cell)
        ii, jj = np.mgrid[-n:n + 1, -n:n + 1]
        held = ndimage.binary_dilation(held, structure=ii ** 2 + jj ** 2 <= n * n) & np.isfinite(reach)
    return reach, held


def _residual(top: np.ndarray, under: np.ndarray, reach: np.ndarray, held: np.ndarray, lo: np.ndarray, cell: float,
              op, cutter, limit: float):
    """The stock left above the finishing tool's reach (:func:`_reach`), normal to it,
    where it reaches."""
    gx, gy = np.meshgrid(*grid_axes(lo, cell, top.shape), indexing="ij")
    # the outline: a node whose neighbours are not all over the part is not judged
    on = np.isfinite(under)
    inner = on.copy()
    inner[1:] &= on[:-1]
    inner[:-1] &= on[1:]
    inner[:, 1:] &= on[:, :-1]
    inner[:, :-1] &= on[:, 1:]
    inner &= np.isfinite(reach) & ~held
    # on the grid the closing can fall below the part at the rim of a wall (the tool just
    # across it): the tool never reaches below the part under the node
    reach = np.maximum(reach, under)
    gxr, gyr = np.gradient(np.where(np.isfinite(reach), reach, np.nan), cell)
    theta = np.degrees(np.arctan(np.hypot(gxr, gyr)))
    steep = inner & ~(np.nan_to_num(theta, nan=90.0) < WALL_SLOPE)
    judged = inner & ~steep
    left = (top - reach) * np.cos(np.radians(np.nan_to_num(theta, nan=90.0)))
    # the stamped sweep lies above the true one by the profile's sag over a quarter cell
    sag = (cell / 4) ** 2 / (2 * max(cutter.corner, cell))
    scallop = float(op.report.get("scallop") or 0.0)
    bound = scallop + limit + sag
    what = f"residual after {op.name} (tool {op.tool.number}, normal to the reachable surface)"
    if not judged.any():
        return Finding(what, -np.inf, bound), int(steep.sum()), int(held.sum())
    vals = np.where(judged, left, -np.inf)
    i, j = np.unravel_index(int(np.argmax(vals)), vals.shape)
    worst = float(vals[i, j])
    over = vals > bound
    labels, _ = ndimage.label(over)
    boxes = tuple((float(gx[a.start, 0]), float(gy[0, b.start]), float(gx[a.stop - 1, 0]), float(gy[0, b.stop - 1]))
                  for a, b in ndimage.find_objects(labels))
    return Finding(what, worst, bound, (float(gx[i, j]), float(gy[i, j]), float(top[i, j])), int(over.sum()),
                   boxes=boxes), int(steep.sum()), int(held.sum())


def body_stand(drop, xy: np.ndarray, tool, slack: float, grow: float = 0.0, clear: float = 0.0, low=None,
               ceiling: float = np.inf) -> np.ndarray:
    """The reach rule, one for the job and its judge: the lowest the tip may stand over each
    (x, y) of ``xy`` for every disc of the tool's shank and holder wider than its end by
    more than ``slack`` (:attr:`~surfmod.cam.tool.Tool.body`; taken ``slack`` narrower, a
    rub within it, and ``grow`` wider) to stand ``clear`` above the part within it: the
    cusps the finishing leaves on the part, counted here and nowhere else
    (:func:`cusp_clearance`).  ``drop(xy, radius)`` is the part's highest point within
    ``radius`` of each (-inf where none).  Returns one row per such disc (none: no rows);
    with the tip's heights ``low``, a disc is dropped only where it stands below
    ``ceiling`` (the part's top), else -inf."""
    rows = []
    for r, h, _ in tool.body:
        if r - slack <= tool.radius:
            continue  # a narrower shank stands in the column the end keeps clear of the part
        row = np.full(len(xy), -np.inf)
        near = np.arange(len(xy)) if low is None else np.flatnonzero(low + h - clear < ceiling)
        if near.size:
            row[near] = drop(xy[near], r - slack + grow) - h + clear
        rows.append(row)
    return np.array(rows).reshape(len(rows), len(xy))


def cusp_left(report: dict, cutter) -> float:
    """The highest cusp a finishing or rest operation (its ``report``, its tool's
    ``cutter``) leaves: its scallop, or the cusp its contours leave a wall of
    ``DEXEL_SLOPE`` where they stand the report's ``spacing`` apart along it, when more (a
    stepover asked of a bull nose, :meth:`~surfmod.cam.cutters.Cutter.wall_cusp`).  The
    walls are judged against it and the holder kept above it (:func:`cusp_clearance`)."""
    spacing = (report.get("waterline") or {}).get("spacing")
    return max(float(report.get("scallop") or 0.0), cutter.wall_cusp(float(spacing), W.DEXEL_SLOPE) if spacing else 0.0)


def cusp_clearance(operations) -> float:
    """The highest cusp the finishing and rest ``operations`` leave (:func:`cusp_left`)
    with its tolerance.  :func:`body_stand` holds every disc of a shank or holder that far
    above the part, in the job and in the verifier's reach alike."""
    return max((cusp_left(o.report, o.tool.cutter) + float(o.report["tolerance"]) for o in operations
                if o.name != "roughing"), default=0.0)


def _wall_residual(part: PartPoints, moves: ProgramMoves, radii: np.ndarray, corners: np.ndarray, stock: np.ndarray,
                   under: np.ndarray, cell: float, op, cutter, limit: float, max_work: int, notes: list, shape,
                   grow: float = 0.0, clear: float = 0.0):
    """The material the program leaves on the part's steep faces where the finishing tool
    reaches, from the dexels along x and y (:mod:`~surfmod.cam.wall_dexels`): ``(finding,
    dexels, points judged)``; ``under`` is the part's top on the height field's nodes
    (``cell`` apart), ``notes`` gets what was coarser than asked; the discs wider than the
    end are taken ``grow`` wider and ``clear`` higher where the tool's reach is asked (as
    the job holds them: its body cell, :func:`cusp_clearance`)."""
    from ..occ.topo import closest_on_face, compound, faces_of

    lo, hi = stock
    what = f"residual on walls after {op.name} (tool {op.tool.number}, normal to the wall)"
    # the dexels kept: round the places the height field sees steep (a wall, the outline)
    sx, sy, zlo, zhi = W.steep_band(under, lo[:2], cell, float(lo[2]), W.DEXEL_SLOPE - 10.0)
    axes = []
    for swap in (False, True):
        order = [1, 0, 2] if swap else [0, 1, 2]
        a0, a1, l0, l1, at = (lo[1], hi[1], lo[0], hi[0], sx) if swap else (lo[0], hi[0], lo[1], hi[1], sy)
        axes.append((swap, np.ascontiguousarray(moves.start[:, order]), np.ascontiguousarray(moves.end[:, order]),
                     a0, a1, l0, l1, at))

    def plan(c):
        levels = int(math.floor((hi[2] - lo[2]) / c))
        out, cuts, kept = [], 0.0, 0
        for swap, a, b, a0, a1, l0, l1, at in axes:
            keep = W.band(np.ascontiguousarray((at - l0) / c + 0.5), zlo, zhi, float(lo[2]), c,
                          int(math.floor((l1 - l0) / c)) + 1, levels)
            any_ = keep.any(axis=1)
            kbot = np.where(any_, np.argmax(keep, axis=1), levels)
            ktop = np.where(any_, levels - 1 - np.argmax(keep[:, ::-1], axis=1), -1)
            cuts += W.sweep_work(a, b, moves.rapid, radii, corners, l0, c, c / 2, kbot, ktop)
            kept += int(keep.sum())
            out.append((swap, a, b, a0, a1, l0, keep, kbot, ktop))
        return out, max(cuts / max_work, kept / MAX_DEXELS)

    wanted = cell
    plans, over = plan(cell)
    while over > 1.0:  # both counts fall at least as the square of the cell: a few rounds
        cell *= 1.05 * math.sqrt(over)
        plans, over = plan(cell)
    if cell > wanted:
        notes.append(f"note: walls: dexels {cell:.3g} mm apart, coarser than the {wanted:.3g} of the stock's cells "
                     f"({max_work:,} cuts, {MAX_DEXELS:,} dexels at most): cusps between their levels are seen "
                     f"lower than they are")
    points, dexels, full = [], 0, 0
    for swap, a, b, a0, a1, l0, keep, kbot, ktop in plans:
        seg = np.empty(keep.shape + (W.SEGMENTS, 2))
        seg[:, :, 0, 0], seg[:, :, 0, 1] = a0, a1
        cnt = keep.astype(np.int64)
        full += W.sweep_dexels(seg, cnt, kbot, ktop, l0, lo[2], cell, a, b, moves.rapid, radii, corners, cell / 2)
        points.append(W.wall_points(seg, cnt, a0, a1, l0, lo[2], cell, swap))
        dexels += int(keep.sum())
    if full:
        notes.append(f"note: walls: {full:,} cuts met a dexel holding {W.SEGMENTS} intervals already and left it "
                     f"whole (more material judged, never less)")
    q = np.concatenate(points)
    # the stock points the part's bounding box (grown by the tool) can reach at all
    box_lo, box_hi = part.points.min(axis=0) - cutter.radius, part.points.max(axis=0) + cutter.radius
    q = q[np.all((q >= box_lo) & (q <= box_hi), axis=1)]
    if len(q) > MAX_WALL_POINTS:
        every = math.ceil(len(q) / MAX_WALL_POINTS)
        notes.append(f"note: walls: every {every}th of {len(q):,} stock points judged ({MAX_WALL_POINTS:,} at most)")
        q = q[::every]
    # the cusps the contours leave on the least steep wall judged: more than the scallop
    # where a stepover was asked
    scallop = cusp_left(op.report, cutter)
    # the stamps' sag between stamps half a cell apart, as in the height field
    bound = scallop + limit + (cell / 4) ** 2 / (2 * max(cutter.corner, cell))
    if not len(q):
        return Finding(what, -np.inf, bound), dexels, 0
    # the part's points near them (their nearest lie within two buckets of a stock point
    # nearer the part than a bucket; a farther one is measured exactly below if deepest);
    # a point farther than a bucket and the bound takes its plane from the part's points
    # one per voxel (a quarter bucket) first: never one the bound holds
    near = part.around(q, 2)
    voxel = part.cell / 4
    depth, normal, foot = W.feet(cKDTree(near), near, q, voxel, max(part.cell, bound + math.sqrt(3) * voxel))
    steep = W.steep_normals(normal)
    q, depth, normal, foot = q[steep], depth[steep], normal[steep], foot[steep]
    tips = W.tangent_tips(foot, normal, cutter.radius, cutter.corner)
    # the tip not below the stock's bottom (the table: a wall's last ``c`` above it is the
    # corner's fillet); the flutes set no floor of their own: a shank no wider than the end
    # follows them down, and what is wider is held against the part below (the job's rule)
    floor = float(lo[2])

    def reached(t):
        """The tool at tips ``t`` (tangent at feet) takes in no point of the part beyond the
        limit, and no disc of its shank or holder wider than the end stands below the part,
        each such disc as wide and as high as the job holds it (grown by its stock model's
        cell, raised by the cusps: where the job keeps a holder out, the wall is not asked
        of it)."""
        ok = (t[:, 2] >= floor - limit) & (part.deepest(t, cutter.radius, cutter.corner)[0] <= limit)
        if ok.any():
            body = body_stand(lambda q, r: part.drop(q, r, 0.0), t[ok, :2], op.tool, limit, grow, clear)
            ok[ok] = np.all(body <= t[ok, 2] + limit, axis=0)
        return ok

    # every point beyond the bound is asked (they are counted), then the next deepest a
    # chunk at a time until one is reached: none asked later lies deeper
    order = np.argsort(-depth)
    asked = int((depth > bound).sum())
    reach = np.zeros(len(q), bool)
    reach[order[:asked]] = reached(tips[order[:asked]])
    for start in range(asked, len(order), REACH_CHUNK):
        if reach.any():
            break
        chunk = order[start:start + REACH_CHUNK]
        reach[chunk] = reached(tips[chunk])
    if not reach.any():
        return Finding(what, -np.inf, bound), dexels, len(q)
    judged, depth_r = q[reach], depth[reach]
    # the deepest measured again against the exact faces, and judged again from the exact
    # foot: the part's points near a stock point may give it a foot on another face than
    # its nearest (a bore's back face under its rim, where the nearest is the overhanging
    # top).  The vector from the nearest point to a point outside is the part's normal there.
    faces = compound(faces_of(shape))
    exact = np.zeros(len(judged), bool)
    for _ in range(EXACT_ROUNDS):
        open_ = np.flatnonzero(~exact & np.isfinite(depth_r))
        k = int(np.argmax(depth_r))
        if not open_.size or exact[k] or depth_r[k] <= bound:  # what is left deepest is settled or within
            break
        top_k = open_[np.argsort(depth_r[open_])[-EXACT_PROBES:]]
        dist, foot = closest_on_face(faces, judged[top_k])
        normal = (judged[top_k] - foot) / np.maximum(dist, 1e-300)[:, None]
        # on the part (within the sampling) a point has no normal of its own: kept
        stays = (dist <= limit) | (W.steep_normals(normal) & reached(W.tangent_tips(foot, normal, cutter.radius,
                                                                                   cutter.corner)))
        depth_r[top_k] = np.where(stays, dist, -np.inf)
        exact[top_k] = True
    k = int(np.argmax(depth_r))
    if not np.isfinite(depth_r[k]):
        return Finding(what, -np.inf, bound), dexels, len(q)
    if not exact[k] and depth_r[k] > bound:
        notes.append(f"note: walls: {EXACT_ROUNDS * EXACT_PROBES} deepest points measured exactly and left by the "
                     f"exact foot, the deepest judged from the part's points")
    return (Finding(what, float(depth_r[k]), bound, tuple(float(v) for v in judged[k]), int((depth_r > bound).sum())),
            dexels, len(q))


def verify_toolpath(path, obj, *, text: str | None = None, max_samples: int = MAX_SAMPLES,
                    max_probes: int = MAX_PROBES) -> Verification:
    """Judge a :class:`~surfmod.cam.toolpath.Toolpath`'s G-code (``text``, default
    ``path.to_gcode()``) against the exact faces of ``obj``: no move may bring a point of
    a face deeper into the tool than the path's tolerance (plus the 4 decimals written).

    >>> import surfmod as sm
    >>> s = sm.plane((0, 0, 1), (10, 0, 1), (0, 10, 1))
    >>> tp = sm.toolpath(s, sm.Tool("ball", 2.0), scallop=0.05)
    >>> verify_toolpath(tp, s).ok
    True
    """
    shape = to_shape(obj, "obj")
    moves = read_program(path.to_gcode() if text is None else text, tool=0)
    # sampled as the path's repair samples it (lift_gouges: one sampling serves both)
    base = float(path.tolerance)
    limit = base + 1e-4
    cutter = path.tool.cutter
    spacing = spacing_for(base / 2, cutter.radius, cutter.corner)
    asked = spacing
    part, spacing = sampled_part(shape, spacing, bucket_cell(spacing, cutter.radius), max_samples, base / 4, fit=True)
    notes = coarser_note(spacing, asked, max_samples)
    found, n, _ = _gouge(part, moves, ~moves.rapid, cutter.radius, cutter.corner, limit, spacing, "gouge",
                         max_probes, notes, shape)
    return Verification((found,), len(part.points), n, spacing=spacing, notes=tuple(notes))
