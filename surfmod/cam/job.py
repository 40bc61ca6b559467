"""A machining job: a part, a block of stock and operations in order (roughing, finishing).

>>> import surfmod as sm, build123d as bd
>>> part = bd.Box(20, 20, 5) + bd.Pos(0, 0, 4) * bd.Cylinder(5, 3)
>>> job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=2.0, allowance=0.3),
...                              sm.Finish(sm.Tool("ball", 1.5), scallop=0.05)])
>>> [op.name for op in job.operations], [op.tool.number for op in job.operations]
(['roughing', 'finishing'], [1, 2])
"""

from __future__ import annotations

import re
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field, replace

import numpy as np
from tqdm import tqdm

from .. import checks
from ..errors import SurfmodError
from ..inputs import to_shape
from .cycle_time import cycle_time, feed_time
from .finishing import Leftover, finish, reach_contours, recut
from .holder import body_stock, clear_body, left_out, reach_levels, relink
from .machine_table import MACHINE, Machine
from .rest import MAX_LOCATIONS, PAIRS_PER_POINT, STEEP_ANGLE, AboveStock, StockModel, left_over, rest_moves
from .rest import summary_line as rest_summary
from .roughing import RAPID, Motion, left_summary, rough
from .tool import Tool
from .toolpath import MAX_WORK, WorkMeter, finish_settings, mesh_estimate, meshed_part
from .verify import cusp_clearance, cusp_left, verify_job

#: Clearance of links and retracts above the stock (mm).
CLEARANCE = 5.0


def roughing_tolerance(allowance: float, stepdown: float, size: float) -> float:
    """The tolerance the roughing's mesh is made for (its deflection is
    :data:`~surfmod.cam.toolpath.MESH_SHARE` of it), graded to what roughing needs, not to
    the finishing's scallop: a quarter of the ``allowance`` (the roughing only has to leave
    the allowance give or take that; the finishing cuts the rest on its own, finer mesh),
    at most a tenth of the ``stepdown`` and 0.05 mm, or 1e-4 of the part's ``size`` on a
    part over 500 mm (a metre-size plate meshes at the allowance, not at a small part's
    0.05); 0.01 mm with no allowance, never below 0.005 mm.

    >>> roughing_tolerance(0.5, 5.0, 80.0), roughing_tolerance(0.5, 30.0, 1000.0), roughing_tolerance(0.0, 5.0, 80.0)
    (0.05, 0.1, 0.01)
    """
    if allowance <= 0:
        return 0.01
    return max(min(allowance / 4, stepdown / 10, max(0.05, 1e-4 * size)), 0.005)


@dataclass(frozen=True)
class Rough:
    """Z-level roughing with ``tool``: levels ``stepdown`` apart (default the tool radius),
    down to the part plus ``allowance``; rings ``stepover`` apart (default 40 % of the
    diameter: the radial engagement)."""

    tool: Tool
    stepdown: float | None = None
    allowance: float = 0.5
    stepover: float | None = None


@dataclass(frozen=True)
class Finish:
    """Finishing with ``tool``: the drop-cutter zig-zag along ``direction`` over the whole
    part plus waterline (constant-Z) contours on the regions steeper than ``steep_angle``
    degrees (None: no contours), spaced so that the cusps measured along the surface stay
    within ``scallop`` on every slope (or passes and contours ``stepover`` apart, the
    contours measured along the walls); see :mod:`surfmod.cam.finishing`."""

    tool: Tool
    scallop: float | None = None
    stepover: float | None = None
    direction: str = "x"
    steep_angle: float | None = 45.0


@dataclass(frozen=True)
class Rest:
    """Rest machining with a smaller ``tool``: it cuts only where the operations ``after``
    (None: all before it in the job; else their positions in the list, from 0, or the
    operations themselves) left more than ``scallop`` (default: the last finishing's)
    plus the tolerance above the part, measured in the job's stock model swept along
    their moves; its passes are its own drop-cutter rasters clipped to those regions
    (:mod:`surfmod.cam.rest`).  A tool no smaller than the finishing's is allowed (it
    still cuts what the stock model shows left where it reaches, e.g. after roughing
    alone) with a warning.  ``max_points`` bounds the passes' raster locations (and a
    hundred times it the thickness test's node-triangle pairs)."""

    tool: Tool
    after: object = None
    scallop: float | None = None
    max_points: int = MAX_LOCATIONS


@dataclass(frozen=True)
class Operation:
    """One operation of a :class:`Job`: its ``name``, ``tool`` (numbered, with speeds and
    feeds), ``motion`` (cutter locations and how the tool moves to each), machining
    ``time_estimate`` (s: the tool change plus the moves as ``machine`` runs them,
    :mod:`surfmod.cam.cycle_time`) and a ``report`` (levels, scallop, rest left...);
    ``feed_time`` is the plain feed-rate sum instead."""

    name: str
    tool: Tool
    motion: Motion = field(repr=False)
    time_estimate: float
    report: dict = field(default_factory=dict, repr=False)
    machine: Machine = field(default=MACHINE, repr=False)
    #: the operation whose motion this one's begins with (a repair's passes appended),
    #: whose program lines the posts reuse
    extends: Operation | None = field(default=None, repr=False, compare=False)

    @property
    def feed_time(self) -> float:
        """Seconds as the plain feed-rate sum (every move at its feed from end to end, no
        acceleration or corner), plus the tool change: what ``time_estimate`` refines."""
        return feed_time(self.motion, self.tool, self.machine) + self.machine.tool_change

    @property
    def moves(self) -> np.ndarray:
        return self.motion.points

    @property
    def length(self) -> float:
        """Length of the cutting moves (feed and plunge), mm."""
        seg = np.linalg.norm(np.diff(self.motion.points, axis=0), axis=1)
        return float(seg[self.motion.kind[1:] != RAPID].sum())

    def __str__(self) -> str:
        m, s = divmod(self.time_estimate, 60)
        text = f"{self.name}: {self.tool}, cutting length {self.length:.0f} mm, time {int(m)} min {s:04.1f} s"
        left = left_summary(self.report.get("left")) if self.name == "roughing" else ""
        if self.name == "rest":
            left = rest_summary(self.report)
        if self.report.get("relinked"):  # rapids the verification found in stock, taken over it
            left = "; ".join(filter(None, [left, f"{self.report['relinked']} rapid(s) through stock re-linked over it"]))
        held = self.report.get("holder")
        text = f"{text}; {left}" if left else text
        return f"{text}; {held}" if held else text


@dataclass(frozen=True)
class Job:
    """The operations of a part machined from ``stock`` (``[[x0, y0, z0], [x1, y1, z1]]``)."""

    part: object = field(repr=False)
    stock: np.ndarray
    operations: tuple
    safe_height: float
    #: what :func:`surfmod.cam.verify.verify_job` found in its LinuxCNC program (None: not verified)
    verification: object = field(default=None, repr=False)
    #: the machine whose limits the time estimates follow
    machine: Machine = field(default=MACHINE, repr=False)

    @property
    def time_estimate(self) -> float:
        return float(sum(op.time_estimate for op in self.operations))

    @property
    def feed_time(self) -> float:
        """The plain feed-rate sum of every operation (see :attr:`Operation.feed_time`)."""
        return float(sum(op.feed_time for op in self.operations))

    def __str__(self) -> str:
        lo, hi = self.stock
        head = (f"job: stock {hi[0] - lo[0]:g} x {hi[1] - lo[1]:g} x {hi[2] - lo[2]:g} mm at "
                f"({lo[0]:g}, {lo[1]:g}, {lo[2]:g}), {len(self.operations)} operations, "
                f"total time {self.time_estimate / 60:.1f} min")
        lines = [head] + [f"  {op}" for op in self.operations]
        if self.verification is not None:
            lines += [f"  {line}" for line in self.verification.lines()]
        return "\n".join(lines)

    def _repr_png_(self) -> bytes:
        from .picture import job_png

        return job_png(self)

    def _repr_html_(self) -> str:
        from .job_view import job_html

        return job_html(self, full_html=False)


def operation_time(motion: Motion, tool: Tool, machine: Machine) -> float:
    """An operation's ``time_estimate``: the tool change plus the moves as ``machine`` runs them."""
    return machine.tool_change + cycle_time(motion, tool, machine)


def stock_box(part_box: np.ndarray, stock) -> np.ndarray:
    """The stock: a margin (the part's box grown on the four sides and on top, its bottom
    at the part's bottom) or an explicit box, which must hold the part."""
    if np.ndim(stock) == 0:
        m = float(stock)
        if not np.isfinite(m) or m < 0:
            raise SurfmodError(f"stock_margin: must be >= 0, got {stock!r}")
        return np.array([part_box[0] - [m, m, 0.0], part_box[1] + [m, m, m]])
    box = checks.finite_array(stock, "stock").reshape(-1)
    if box.shape != (6,):
        raise SurfmodError(f"stock: expected X0 Y0 Z0 X1 Y1 Z1, got {np.asarray(stock).tolist()}")
    box = np.sort(box.reshape(2, 3), axis=0)
    slack = 1e-6 * float(np.ptp(part_box, axis=0).max())
    if np.any(box[0] > part_box[0] + slack) or np.any(box[1] < part_box[1] - slack):
        raise SurfmodError(f"stock: the box {box.ravel().tolist()} is smaller than the part "
                           f"{np.round(part_box.ravel(), 4).tolist()}")
    return box


#: keywords of the refusals inside a stage that neither ``sm.machine`` nor ``surfmod machine``
#: takes: a stage re-raises them naming its own option (:func:`_stage`)
INNER_KEYWORDS = ("max_work", "max_points", "max_samples", "max_probes", "tolerance", "sampling")


@contextmanager
def _stage(bar, what: str, option: str, advice: str):
    """One stage of :func:`machine`, shown on ``bar`` while it runs and counted on it when
    done.  Every stage estimates its work before it starts and refuses above its cap; a
    refusal that names an inner keyword (:data:`INNER_KEYWORDS`, e.g. ``max_work`` of the
    drop-cutter) is re-raised in one line naming ``option``, which the job's operations and
    the command's flags have, with ``advice`` on how to change it."""
    bar.set_postfix_str(what)
    with _options(what, option, advice):
        yield
    bar.update()


@contextmanager
def _options(what: str, option: str, advice: str):
    """A refusal naming an inner keyword (:data:`INNER_KEYWORDS`) re-raised in one line
    naming ``option`` (see :func:`_stage`)."""
    try:
        yield
    except SurfmodError as exc:
        keyword, _, text = str(exc).partition(": ")
        if keyword not in INNER_KEYWORDS:
            raise
        text = re.sub(r"; pass \w+= a larger value to allow it$", "", text)
        raise SurfmodError(f"{option}: the {what} ({keyword}): {text}; {advice}") from None


def _rough_settings(op: Rough, tool: Tool, box: np.ndarray) -> tuple:
    """``(stepdown, stepover, allowance, mesh tolerance)`` of a roughing, checked."""
    stepdown = tool.radius if op.stepdown is None else checks.positive(op.stepdown, "stepdown")
    stepover = 0.8 * tool.radius if op.stepover is None else checks.positive(op.stepover, "stepover")
    if stepover >= tool.radius:
        raise SurfmodError(f"stepover: roughing needs a stepover below the tool radius {tool.radius:g}")
    allowance = float(op.allowance)
    if not np.isfinite(allowance) or allowance < 0:
        raise SurfmodError(f"allowance: must be >= 0, got {op.allowance!r}")
    return stepdown, stepover, allowance, roughing_tolerance(allowance, stepdown, float(np.max(box[1] - box[0])))


def _finish_settings(op: Finish, tool: Tool) -> tuple:
    """``(stepover or None, steep angle or None, tolerance)`` of a finishing, checked
    (:func:`~surfmod.cam.toolpath.finish_settings`: a scallop the tool cannot leave is
    refused here, before the roughing runs)."""
    stepover, tolerance = finish_settings(tool, op.stepover, op.scallop, op.direction)
    steep = op.steep_angle
    if steep is not None:
        steep = float(steep)
        if not 0.0 < steep <= 90.0:
            raise SurfmodError(f"steep_angle: must be in (0, 90] degrees, got {op.steep_angle!r}")
    if op.scallop is not None:
        return None, steep, op.scallop / 10
    return stepover, steep, tolerance


def _finish(shape, op: Finish, tool: Tool, stock: np.ndarray, safe: float, rest: Leftover | None,
            progress: bool = False, estimate: float | None = None):
    stepover, steep, tolerance = _finish_settings(op, tool)
    # every drop of the finishing is charged to one cap, estimated before the raster
    # starts; a small tool on a fine scallop is refused there, naming the scallop, and
    # the bar counts the triangle tests (the finishing is most of a small tool's job)
    with tqdm(total=1, desc="finishing", unit=" tests", unit_scale=True, leave=False, disable=not progress) as bar:
        meter = WorkMeter(MAX_WORK, bar if progress else None, "scallop",
                       f"choose a larger scallop than {op.scallop:g} or a larger finishing tool"
                       if op.scallop is not None else "choose a larger stepover or a larger finishing tool")
        part = meshed_part(shape, tool.cutter, tolerance, meter, estimate, clear=True)
        motion, report = finish(part, tool, scallop=op.scallop, stepover=stepover, direction=op.direction,
                                steep_angle=steep, tolerance=tolerance, stock=stock, safe=safe, rest=rest)
        bar.total = max(bar.n, 1)  # the contours' drops came after the raster's estimate: the bar ends full
    part.meter.bar = None  # the repairs (re-cut passes) run after the bar is closed
    return motion, report, part


def _recut(job: Job, finishing: dict, stock: StockModel) -> Job:
    """One round of repair: where the verification found the last finishing's scallop
    broken, cross passes over those regions (:func:`surfmod.cam.finishing.recut`) are
    added to it, and the job is judged again.  Moves of the passes whose shank or holder
    would collide are left out (:func:`surfmod.cam.holder.clear_body`); the verdict then
    stands where they were."""
    found = next((f for f in job.verification.findings if f.what.startswith("residual") and not f.ok), None)
    if found is None or not found.boxes or not finishing:
        return job
    k = max(finishing)
    if any(o.name == "rest" for o in job.operations[k + 1:]):
        return job  # the residual judged is the rest tool's, which cross passes of the finishing do not serve
    op, (spec, part, rest, floor) = job.operations[k], finishing[k]
    extra, passes = recut(part, op.tool, found.boxes, stepover=float(op.report["stepover"]), direction=spec.direction,
                          tolerance=float(op.report["tolerance"]), stock=job.stock, safe=job.safe_height, rest=rest,
                          over=found.worst / found.limit, raster=op.report.get("toolpath"))
    if passes == 0:
        return job
    extra, _ = clear_body(extra, op.tool, stock, part.grid.triangles, part.deflection, float(op.report["tolerance"]),
                          job.safe_height, job.part, cusp_clearance(job.operations), wall_skin(job.operations), floor)
    if not np.any(extra.kind != RAPID):
        return job
    motion = Motion(np.concatenate([op.motion.points, extra.points]), np.concatenate([op.motion.kind, extra.kind]))
    seg = np.linalg.norm(np.diff(extra.points, axis=0), axis=1)
    report = dict(op.report, recut={"regions": len(found.boxes), "passes": passes, "before": found.worst,
                                    "length": float(seg[extra.kind[1:] != RAPID].sum())})
    ops = list(job.operations)
    ops[k] = replace(op, motion=motion, time_estimate=operation_time(motion, op.tool, op.machine), report=report,
                     extends=op)
    job = replace(job, operations=tuple(ops))
    return replace(job, verification=verify_job(job, before=job.verification))


def wall_skin(operations) -> float:
    """The allowance the roughing ``operations`` leave on the walls, the thickest, since the
    last finishing or rest operation (whose contours cut it)."""
    last = max((k for k, o in enumerate(operations) if o.name != "roughing"), default=-1)
    return max((float(o.report["allowance"]) for o in operations[last + 1:] if o.name == "roughing"), default=0.0)


def _held(motion, tool, stock_model, part, tolerance, safe, strict, name, shape, cusp, skin, floor, contours=None):
    """``(motion, held, levels)``: the operation's moves cleared of shank and holder
    collisions, a disc clearing the part by ``cusp`` (``skin``: :func:`wall_skin`), and
    where that left waterline contours out, those again at the holder's reach
    (:func:`_at_reach`, given the operation's ``contours``: their ``spacing``,
    ``steep_angle`` and where the stock stands for :func:`~surfmod.cam.finishing.reach_contours`;
    None: it has none) in ``levels`` levels; with ``strict`` a collision refuses the job.
    ``floor``: the part's top over the model's nodes, computed once per operation."""
    motion, held = clear_body(motion, tool, stock_model, part.grid.triangles, part.deflection, tolerance, safe,
                              shape, cusp, skin, floor)
    if held is not None and strict:
        raise SurfmodError(f"strict: the {name} with {tool}: {held} (a longer tool: flute_length, shank_length; "
                           f"a narrower holder; or strict=False to leave it)")
    if held is None or contours is None:
        return motion, held, 0
    return _at_reach(motion, held, tool, stock_model, part, tolerance, safe, shape, cusp, skin, contours, floor)


def _at_reach(motion, held, tool, stock_model, part, tolerance, safe, shape, cusp, skin, contours, floor):
    """Where the holder check left waterline contours out, those contours again at the
    lowest height the shank and holder let the tool cut there, themselves held and
    appended; returns the motion, what is left out in all and the levels added (see
    :func:`_held`)."""
    spacing = contours["spacing"]
    groups = reach_levels(held, tool, stock_model, part.grid.triangles, part.deflection, tolerance, cusp,
                          spacing / 2, skin, floor)
    if not groups:
        return motion, held, 0
    extra = reach_contours(part, tool, groups, tolerance=tolerance, safe=safe, **contours)
    if not np.any(extra.kind != RAPID):
        return motion, held, 0
    extra, again = clear_body(extra, tool, stock_model, part.grid.triangles, part.deflection, tolerance, safe, shape,
                              cusp, skin, floor)
    cuts = held.cuts if again is None else np.concatenate([held.cuts, again.cuts])
    held = left_out(stock_model, tool, cuts[:, 0], cuts[:, 1], held.moves + (again.moves if again else 0), tolerance)
    return (Motion(np.concatenate([motion.points, extra.points]), np.concatenate([motion.kind, extra.kind])), held,
            len(groups))


#: how far (mm) a move the verifier read from the program may lie from the motion it was
#: written from: the posts write 4 decimals
PROGRAM_ROUNDING = 1e-3


def _relink(job: Job) -> Job:
    """One round of repair: every rapid the verification found running through stock is
    left out and the tool re-linked over it (:func:`surfmod.cam.holder.relink`: up to the
    job's safe height, across, and down at the plunge feed), and the job is judged again.
    A rapid the program holds but no operation's motion does (none today) is left, and
    its verdict stands."""
    found = next((f for f in job.verification.findings if f.what == "rapids" and f.segments), None)
    if found is None:
        return job
    ops, relinked = list(job.operations), 0
    for k in sorted({seg[0] for seg in found.segments}):
        op = ops[k]
        pts, kind = op.motion.points, op.motion.kind
        removed = np.zeros(len(pts) - 1, bool)  # per move into points[i + 1]
        for _, a, b in (seg for seg in found.segments if seg[0] == k):
            removed |= ((kind[1:] == RAPID) & (np.abs(pts[:-1] - a).max(axis=1) <= PROGRAM_ROUNDING)
                        & (np.abs(pts[1:] - b).max(axis=1) <= PROGRAM_ROUNDING))
        if not removed.any():
            continue
        motion = relink(op.motion, removed, job.safe_height)
        ops[k] = replace(op, motion=motion, time_estimate=operation_time(motion, op.tool, op.machine),
                         report=dict(op.report, relinked=int(removed.sum())))
        relinked += int(removed.sum())
    if not relinked:
        return job
    job = replace(job, operations=tuple(ops))
    return replace(job, verification=verify_job(job, before=job.verification))


def _after(op: Rest, k: int, specs: list) -> list[int]:
    """The positions of the operations a rest operation at position ``k`` follows."""
    if k == 0:
        raise SurfmodError("after: a rest operation needs an operation before it")
    if op.after is None:
        return list(range(k))
    items = list(op.after) if isinstance(op.after, (list, tuple)) else [op.after]
    out = []
    for a in items:
        if isinstance(a, (Rough, Finish, Rest)):
            idx = next((i for i in range(k) if specs[i] is a), None)
        elif isinstance(a, (int, np.integer)) and not isinstance(a, bool) and 0 <= a < k:
            idx = int(a)
        else:
            idx = None
        if idx is None:
            raise SurfmodError(f"after: expected operations before the rest operation (positions 0..{k - 1} "
                               f"or the operations themselves), got {a!r}")
        out.append(idx)
    if not out:
        raise SurfmodError("after: give at least one operation before the rest operation")
    return sorted(set(out))


def _rest(shape, op: Rest, tool: Tool, k: int, specs: list, done: list, stock: np.ndarray, safe: float, held):
    """The rest operation's motion and report (:mod:`surfmod.cam.rest`); ``held`` clears
    its moves of shank and holder collisions (:func:`_held`, given the moves, the part, the
    tolerance, the scallop and its contours)."""
    after = _after(op, k, specs)
    cutting = [done[i] for i in after if done[i].name != "roughing"]
    if op.scallop is not None:
        scallop = checks.positive(op.scallop, "scallop")
    elif cutting:
        scallop = float(cutting[-1].report["scallop"])
    else:
        raise SurfmodError("scallop: give the rest operation's scallop (no finishing before it)")
    stepover = tool.stepover_for_scallop(scallop)  # a scallop >= the radius raises here
    smallest = min((o.tool.radius for o in cutting), default=None)
    if smallest is not None and tool.radius >= smallest:
        warnings.warn(f"rest: {tool} is no smaller than the tools before it (r={smallest:g}): it cuts only what "
                      f"the stock model shows left where it reaches", UserWarning, stacklevel=3)
    tolerance = scallop / 10
    part = meshed_part(shape, tool.cutter, tolerance, clear=True)
    cell = max(min([stepover] + [float(o.report["stepover"]) for o in cutting]) / 4, 1e-3)
    model = StockModel(stock, cell)
    for i in after:
        model.sweep(done[i].motion, done[i].tool)
    part_top = model.part_top(part.grid.triangles)
    threshold = scallop + tolerance + model.sag
    pairs = op.max_points * PAIRS_PER_POINT
    mask, before = left_over(model, part_top, part, threshold, pairs)
    # the contours go down to the stock's bottom, as the finishing's: the holder check
    # (``held``) decides how deep the tool goes, not its flutes
    motion, info = rest_moves(part, tool, model, mask, scallop=scallop, stepover=stepover, tolerance=tolerance,
                              safe=safe, bottom=float(stock[0, 2]), max_points=op.max_points)
    # its contours again at the holder's reach where it left them out, as the finishing's
    contours = (dict(spacing=info["spacing"], steep_angle=STEEP_ANGLE, top=AboveStock(model, tool.radius, safe))
                if info["levels"] else None)
    motion, kept_out, levels = held(motion, part, tolerance, scallop, contours)
    if levels:
        info["at_reach"] = levels
    model.sweep(motion, tool)
    _, left = left_over(model, part_top, part, threshold, pairs)
    report = dict(info, after=after, scallop=scallop, stepover=stepover, tolerance=tolerance, threshold=threshold,
                  cell=model.cell, before=before, left=left, deflection=part.deflection, holder=kept_out)
    if model.note:
        report["note"] = model.note
    return motion, report


def machine(part, stock, operations, *, progress: bool = False, verify: bool = True,
            machine: Machine = MACHINE, strict: bool = False) -> Job:
    """Machine ``part`` (a build123d shape, STEP path or surfmod surfaces) from ``stock``
    (a margin in mm, or a box ``[[x0, y0, z0], [x1, y1, z1]]`` holding the part) by
    ``operations`` in order (:class:`Rough`, :class:`Finish`, :class:`Rest`); tools without a number get
    1, 2, ... in that order, and speeds and feeds from their diameter.  Roughing clears the
    stock down to the part plus its allowance (:mod:`surfmod.cam.roughing`); finishing is
    the gouge-checked drop-cutter path (:func:`surfmod.toolpath`) plus waterline contours on
    the steep regions, with the rest it cannot reach reported
    (:mod:`surfmod.cam.finishing`); rest machining cuts with a smaller tool where the
    job's stock model shows more than the scallop left (:mod:`surfmod.cam.rest`).

    Above the flutes a tool does not cut: every move whose shank or holder
    (:attr:`Tool.body <surfmod.cam.tool.Tool.body>`) would touch the part or the stock is
    left out, the tool going round it by the clearance height, and what is left uncut is
    reported in the operation's ``report["holder"]`` (:class:`~surfmod.cam.holder.Held`:
    area, deepest point; see :mod:`surfmod.cam.holder`).  That is the only bound on how
    deep a tool goes: not its flutes (a shank no wider than the end follows them down a
    hole).  With ``strict`` such a collision raises ``SurfmodError`` instead.

    With ``verify`` (the default) the job's LinuxCNC program is read back and judged
    against the exact part and the stock (:func:`surfmod.cam.verify.verify_job`: gouge,
    rapids through stock or part, the scallop left); where the scallop is broken, cross
    passes over those regions are added to the finishing (its ``report["recut"]``) and the
    job is judged again.  ``job.verification`` holds what was found last,
    ``job.verification.ok`` whether every promise holds.

    ``machine`` (a :class:`~surfmod.cam.machine_table.Machine`: axis velocities and
    accelerations, rapid rate, corner blending, tool change) is what the operations'
    ``time_estimate`` follow (:mod:`surfmod.cam.cycle_time`); by default a small hobby mill."""
    from ..occ.properties import bounding_box

    shape = to_shape(part, "part")
    ops = list(operations) if isinstance(operations, (list, tuple)) else [operations]
    if not isinstance(machine, Machine):
        raise SurfmodError(f"machine: expected a surfmod Machine, got {type(machine).__name__}")
    if not ops or not all(isinstance(o, (Rough, Finish, Rest)) for o in ops):
        raise SurfmodError("operations: expected a list of sm.Rough / sm.Finish / sm.Rest")
    wrong = next((o.tool for o in ops if not isinstance(o.tool, Tool)), None)
    if wrong is not None:
        raise SurfmodError(f"tool: expected a surfmod Tool, got {type(wrong).__name__}")
    box = bounding_box(shape.wrapped if hasattr(shape, "wrapped") else shape)
    if not np.all(np.isfinite(box)) or np.any(box[1] - box[0] <= 0):
        raise SurfmodError("part: has no solid extent to machine")
    stock = stock_box(box, stock)
    safe = float(stock[1, 2] + CLEARANCE)
    strict = bool(strict)
    # a mesh that would be refused is refused before any operation runs (an 80-20 rail
    # 1.2 m long had its finishing refused after 9 minutes of roughing)
    # (each estimate is passed on to the operation's meshing, which then skips the check)
    estimates = {}
    for k, op in enumerate(ops):
        tool = op.tool.with_defaults(k + 1)
        if isinstance(op, Rough):
            with _options("roughing's mesh", "allowance", "a larger allowance meshes coarser"):
                estimates[k] = mesh_estimate(shape, _rough_settings(op, tool, box)[3])
        elif isinstance(op, Finish):
            with _options("finishing's mesh", "scallop", "choose a larger scallop or finishing tool"):
                estimates[k] = mesh_estimate(shape, _finish_settings(op, tool)[2])
    # the stock model the shanks and holders are held against, shared by the operations
    stock_model = body_stock(stock, min(o.tool.radius for o in ops))
    done, rest, finishing = [], None, {}
    numbers = {}
    # the bar counts stages (two per operation, the verification); the finishing's own
    # bar its drop-cutter work (triangle tests) and the waterline's levels while it runs
    with tqdm(total=2 * len(ops) + bool(verify), desc="machine", unit="stage", disable=not progress) as bar:
        for k, op in enumerate(ops):
            tool = op.tool.with_defaults(k + 1)
            if numbers.setdefault(tool.number, tool) != tool:
                raise SurfmodError(f"tool: number {tool.number} is given to two different tools")
            if isinstance(op, Rough):
                stepdown, stepover, allowance, tolerance = _rough_settings(op, tool, box)
                grown = tool.cutter.roughing_offset(allowance) if allowance > 0 else tool.cutter
                with _stage(bar, "roughing's mesh", "allowance", "a larger allowance meshes coarser"):
                    p = meshed_part(shape, grown, tolerance, estimate=estimates[k])
                with _stage(bar, "roughing", "stepdown", "a larger stepdown or roughing tool"):
                    motion, report = rough(p.grid, p.lift, grown, tool, allowance, stock, stepdown, stepover,
                                           CLEARANCE, deflection=p.deflection)
                    motion, held, _ = _held(motion, tool, stock_model, p, tolerance, safe, strict, "roughing", shape,
                                            cusp_clearance(done), wall_skin(done),
                                            stock_model.part_top(p.grid.triangles))
                report.update(allowance=allowance, stepdown=stepdown, stepover=stepover, tolerance=tolerance,
                              holder=held)
                rest = Leftover(tool.radius + allowance, allowance + stepdown + p.lift, allowance + p.lift)
                name = "roughing"
            elif isinstance(op, Rest):
                bar.update()
                with _stage(bar, "rest machining", "scallop", "a larger scallop or rest tool"):
                    motion, report = _rest(shape, op, tool, k, ops, done, stock, safe,
                                           lambda m, part, tol, scallop, contours: _held(
                                               m, tool, stock_model, part, tol, safe, strict, "rest machining", shape,
                                               max(cusp_clearance(done), scallop + tol), wall_skin(done),
                                               stock_model.part_top(part.grid.triangles), contours))
                name = "rest"
            else:
                bar.update()
                # the contours go down to the stock's bottom: how deep the tool goes is its
                # body's to say (a shank no wider than the end follows the flutes down a
                # hole; the holder stops where it would meet the part or the stock)
                with _stage(bar, "finishing", "scallop", "a larger scallop or finishing tool"):
                    motion, report, finish_part = _finish(shape, op, tool, stock, safe, rest, progress, estimates[k])
                    tolerance = float(report["tolerance"])
                    # its own cusps too: a holder coming down beside the part passes over them
                    cusp = max(cusp_clearance(done), cusp_left(report, tool.cutter) + tolerance)
                    w = report.get("waterline")
                    contours = (dict(spacing=w["spacing"], steep_angle=report["steep_angle"], stock=stock, rest=rest)
                                if w and w["levels"] else None)
                    floor = stock_model.part_top(finish_part.grid.triangles)  # the repair reuses it
                    motion, held, levels = _held(motion, tool, stock_model, finish_part, tolerance, safe, strict,
                                                 "finishing", shape, cusp, wall_skin(done), floor, contours)
                    if levels:
                        w["at_reach"] = levels
                finishing[k] = (op, finish_part, rest, floor)
                report["holder"] = held
                name = "finishing"
            done.append(Operation(name, tool, motion, operation_time(motion, tool, machine), report, machine))
        job = Job(shape, stock, tuple(done), safe, machine=machine)
        if verify:
            with _stage(bar, "verification", "verify", "verify=False, surfmod machine --no-verify, skips it"):
                job = _relink(_recut(replace(job, verification=verify_job(job)), finishing, stock_model))
            # what the repairs reused is not kept with the job
            job = replace(job, verification=replace(job.verification, measured={}))
    return job
