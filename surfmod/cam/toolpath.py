"""NC tool paths for continuous-path machining: drop-cutter zig-zag rasters that never gouge.

The same concept as :mod:`surfmod.cli.toolpath` (the ``surfmod toolpath`` command over it),
one level down.  The tool is dropped onto the part's faces meshed inside their trims and
measured against them; every move is checked along its length
(:mod:`surfmod.cam.toolpath_moves`) and against the exact faces' points, what still cuts is
lifted (``Toolpath.lifted``), and a path that cuts deeper than the tolerance raises: gouging
G-code is never returned.  See :doc:`/guide/cam` (section "From a NURBS surface to G-code").
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from tqdm import tqdm

from .. import checks
from ..errors import SurfmodError
from ..inputs import to_shape
from ..readback import from_face
from ..meshing.brep import triangle_estimate
from ..meshing.render import Drawing, polyline_runs, repr_png
from .cutters import Cutter
from .drop_cutter import TriangleGrid, drop, part_triangles
from .part_points import lift_gouges
from .post import round_up
from .toolpath_exact import exact_heights, polish
from .tool import Tool
from .toolpath_moves import NoSafePathError, lift_moves, move_gouge, raster, refine_moves, staircase_steep

# Shares of the gouge tolerance: the mesh's chordal deflection, and the depth at which
# the refinement inserts a location (the rest is the margin between sample points).
MESH_SHARE = 0.4
REFINE_SHARE = 0.5
# More cutter locations than this is a mistake in step/stepover, not a finishing path.
MAX_LOCATIONS = 2_000_000
#: triangles the part's mesh may need by the curvature estimate (meshing/brep), checked
#: before BRepMesh runs: the drop grid indexes each triangle in ~25 cells
MAX_TRIANGLES = 2_000_000
#: tolerances below this fraction of the part's diagonal are refused before meshing:
#: BRepMesh's time is not in the curvature estimate there (a 6 x 4 x 3 boss at 1.3e-7 of
#: its size: 15 s of BRepMesh for planes around one cylinder); the documented setting
#: (ball of 3 % of the part, scallop 2 % of the ball) asks 5e-5
TOLERANCE_FLOOR = 1e-6
#: drop-cutter work one path may take, in triangle tests (cell-list entries a drop may
#: walk, an upper bound: the walk stops early on most lists).  The costliest corpus part
#: at the documented setting (Ventilator, ball of 3 % of the part, scallop 2 % of the
#: ball) takes 1.0e10 of them in 42 s of one core; the cap is about twice that
MAX_WORK = 25_000_000_000
#: drops per raster location a path costs at the least: two refinement passes of two
#: samples per move, the verdict's four, a repair's two and its verdict's four, the contacts
NOMINAL_DROPS = 17


@dataclass(frozen=True)
class Toolpath:
    """A continuous zig-zag tool path, verified move by move.

    ``points`` ``(N, 3)``: cutter locations (tool tip) in machining order, one continuous
    polyline (passes joined by links, refined where straight moves would cut, staircases
    at walls); ``contacts`` ``(N, 3)``: where the dropped tool touches the part at each
    location's (x, y) (NaN where it touches nothing); ``pass_index`` ``(N,)``: raster pass
    of each point (-1 on links and staircases).  ``gouge``: the deepest any move was found
    below the drop-cutter height (≤ 0: nowhere), ``deflection``: the mesh's chordal
    deflection, ``tolerance``: the depth no move may cut (``gouge + deflection`` is within it),
    ``lifted``: the most any location was raised above its drop-cutter height where
    refining could not keep a move from cutting (0: nowhere; material is left there).

    >>> import surfmod as sm
    >>> flat = sm.plane((0, 0, 0), (10, 0, 0), (0, 10, 0))
    >>> tp = sm.toolpath(flat, sm.Tool("ball", 1.0), stepover=1.0)
    >>> float(tp.points[:, 2].min()), tp.gouge + tp.deflection <= tp.tolerance   # tip rides on z = 0
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
    tolerance: float
    deflection: float
    lifted: float = 0.0

    @property
    def n_passes(self) -> int:
        return int(self.pass_index.max()) + 1

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.diff(self.points, axis=0), axis=1).sum())

    def to_gcode(self, *, feed: float = 600.0, plunge_feed: float | None = None, safe_height: float | None = None,
                 spindle: float | None = None, digits: int = 4) -> str:
        """The G-code text (millimetres, absolute; written by :func:`surfmod.export_gcode`).
        Heights are rounded up to ``digits`` decimals, so the written path never sits lower
        than the verified one; x and y are rounded to nearest.

        >>> import surfmod as sm
        >>> tp = sm.toolpath(sm.plane((0, 0, 0), (2, 0, 0), (0, 2, 0)), sm.Tool("flat", 1.0), stepover=1.5)
        >>> [ln for ln in tp.to_gcode().splitlines() if ln.startswith("G1 ")][:2]
        ['G1 Z0.0000 F200', 'G1 X0.2500 Y0.0000 Z0.0000 F600']
        """
        feed = checks.positive(feed, "feed")
        plunge = feed / 3 if plunge_feed is None else checks.positive(plunge_feed, "plunge_feed")
        if int(digits) != digits or not 0 <= digits <= 8:
            raise SurfmodError(f"digits: expected an integer 0..8, got {digits!r}")
        digits = int(digits)
        points = np.array(self.points, dtype=float)
        points[:, 2] = round_up(points[:, 2], digits)
        top = float(points[:, 2].max())
        if safe_height is None:
            safe = top + max(5.0, self.tool.radius)
        else:
            safe = float(checks.finite_array(safe_height, "safe_height"))
            if safe <= top:
                raise SurfmodError(f"safe_height: {safe:g} must be above the highest path point {top:.6g}")
        number = f"{{:.{digits}f}}"
        lines = [
            "%",
            f"(surfmod drop-cutter zig-zag: {self.tool.cutter.comment})",
            f"(stepover {self.stepover:.6g} mm, scallop {self.scallop:.4g} mm, {len(points)} points)",
            f"(every move checked: no cut deeper than {self.tolerance:.4g} mm)",
            "G21 (millimetres)", "G90 (absolute)", "G17 (XY plane)",
        ]
        if spindle is not None:
            lines.append(f"S{checks.positive(spindle, 'spindle'):.0f} M3")
        x0, y0, z0 = points[0]
        lines += [
            f"G0 Z{number.format(safe)}",
            f"G0 X{number.format(x0)} Y{number.format(y0)}",
            f"G1 Z{number.format(z0)} F{plunge:g}",
        ]
        columns = [np.char.mod(f"%.{digits}f", points[1:, k]) for k in range(3)]
        body = list(np.char.add(np.char.add(np.char.add("G1 X", columns[0]), np.char.add(" Y", columns[1])),
                                np.char.add(" Z", columns[2])))
        if body:
            body[0] = f"{body[0]} F{feed:g}"
        lines += body
        lines += [f"G0 Z{number.format(safe)}"]
        if spindle is not None:
            lines.append("M5")
        lines += ["M2", "%", ""]
        return "\n".join(lines)

    def drawing(self) -> list[Drawing]:
        """The path as lines for :func:`surfmod.render`: raster passes in blue, links and
        staircases (``pass_index`` -1) in orange."""
        on_pass = (self.pass_index[1:] >= 0) & (self.pass_index[1:] == self.pass_index[:-1])
        runs = polyline_runs(self.points, on_pass)
        return [
            Drawing(lines=runs.get(True, []), line_color=(0.1, 0.3, 0.8, 0.9), line_width=0.7),
            Drawing(lines=runs.get(False, []), line_color=(0.95, 0.5, 0.1, 0.9), line_width=0.7),
        ]

    def _repr_png_(self) -> bytes | None:
        """A picture of the moves for Jupyter (see :func:`surfmod.meshing.render.png_bytes`)."""
        return repr_png(self)

    def __str__(self) -> str:
        return (
            f"toolpath: {self.tool.cutter.summary}, {self.n_passes} passes along {self.direction}, "
            f"{len(self.points)} points, stepover {self.stepover:.6g} (scallop {self.scallop:.3g} on flat ground), "
            f"length {self.length:.6g}, every move checked: max gouge {max(self.gouge + self.deflection, 0.0):.2e} "
            f"(tolerance {self.tolerance:.2e})"
            + (f", moves lifted by up to {self.lifted:.3g} where refining could not follow the part (material left)"
               if self.lifted > 0 else "")
        )


class WorkMeter:
    """The drop-cutter work of one path against its cap, charged before each drop (so a
    refusal comes before the work), shown on the progress bar.  ``flag`` and ``hint``
    name what the caller can change (``surfmod machine`` has no ``max_work``: its
    finishing names ``--scallop``); by default the refusal names ``max_work``."""

    def __init__(self, cap: float = np.inf, bar=None, flag: str | None = None, hint: str = ""):
        self.used, self.cap, self.bar = 0, cap, bar
        self.flag, self.hint = flag, hint

    def refuse(self, estimate: float, what: str) -> None:
        """Raise when ``estimate`` triangle tests pass the cap."""
        if estimate <= self.cap:
            return
        if self.flag is None:
            checks.work(estimate, int(self.cap), "max_work", what)
        raise SurfmodError(f"{self.flag}: {what} needs about {estimate:,.0f} triangle tests, above the cap "
                               f"{int(self.cap):,}; {self.hint}")

    def charge(self, work: int, what: str) -> None:
        if self.used + work > self.cap:
            self.refuse(self.used + work, f"the drop-cutter ({what}, after {self.used:,} triangle tests)")
        self.used += work
        if self.bar is not None:
            if self.used > self.bar.total:  # more refinement than estimated: the bar grows, never stalls at 100 %
                self.bar.total = int(self.used * 1.25)
            self.bar.update(work)


@dataclass(frozen=True)
class MeshedPart:
    """The machined part for one tool: its mesh on a query grid, and the lift that covers
    a mesh deflection larger than requested."""

    grid: TriangleGrid
    cutter: Cutter  # of the grid's radius
    deflection: float
    lift: float
    box: np.ndarray
    faces: list = field(default_factory=list, repr=False)  # OCCT faces, and the face of each triangle
    owner: np.ndarray = field(default=None, repr=False)
    meter: WorkMeter = field(default_factory=WorkMeter, repr=False)

    def height(self, xy: np.ndarray) -> np.ndarray:
        """Tip heights at ``xy`` (N, 2), NaN where the tool touches nothing."""
        self.meter.charge(self.grid.entries(xy), f"{len(xy):,} locations")
        return drop(self.grid, self.cutter, xy) + self.lift


def mesh_estimate(shape, tolerance: float) -> float:
    """The curvature estimate of the part's mesh at ``tolerance`` (triangles); refuses,
    before BRepMesh runs, a tolerance whose estimate exceeds :data:`MAX_TRIANGLES` or
    which lies below :data:`TOLERANCE_FLOOR` of the part's size."""
    from ..occ.properties import bounding_box

    box = bounding_box(shape, optimal=False)
    diag = float(np.linalg.norm(box[1] - box[0]))
    tolerance = checks.tolerance(tolerance, "tolerance", diag)
    if tolerance < TOLERANCE_FLOOR * diag:
        raise SurfmodError(f"tolerance: {tolerance:g} is below {TOLERANCE_FLOOR:g} x the part size {diag:.3g} "
                           f"(BRepMesh's time grows without bound below it)")
    deflection = MESH_SHARE * tolerance
    estimate, _ = triangle_estimate(shape, deflection)
    if estimate > MAX_TRIANGLES:
        raise SurfmodError(
            f"tolerance: {tolerance:.3g} meshes the part at deflection {deflection:.3g}, about "
            f"{estimate:,.0f} triangles, above the limit {MAX_TRIANGLES:,} (a larger tolerance or scallop)")
    return float(estimate)


def meshed_part(obj, cutter: Cutter, tolerance: float, meter: WorkMeter | None = None, estimate: float | None = None, *,
          clear: bool = False) -> MeshedPart:
    """The part meshed for ``tolerance``; ``estimate`` is :func:`mesh_estimate`'s value
    when the caller has already checked this tolerance (the survey costs 0.4 s on a
    280 mm mould), else the check runs here.  With ``clear`` the cutter is grown by the
    mesh's deflection ``δ`` (:meth:`~surfmod.cam.cutters.Cutter.grown`) and every height
    lifted by ``δ``: the heights keep the tool ``δ`` from every triangle in every
    direction, so it never touches the faces the mesh stands for (a vertical lift by
    ``δ`` would not do on a wall of slope θ: there the mesh's ``δ`` is ``δ / cos θ`` deep
    measured vertically); the grid is built once, for the grown radius."""
    shape = to_shape(obj, "obj")
    requested = MESH_SHARE * tolerance
    if estimate is None:
        mesh_estimate(shape, tolerance)
    try:
        triangles, measured, (faces, owner) = part_triangles(shape, requested, face_index=True)
    except SurfmodError as exc:
        raise NoSafePathError(f"toolpath: no safe path: {exc}") from None
    points = triangles.reshape(-1, 3)
    box = np.array([points.min(axis=0), points.max(axis=0)])
    deflection = max(measured, requested)
    lift = max(measured - requested, 0.0)
    if clear:
        cutter, lift = cutter.grown(deflection), deflection
    return MeshedPart(TriangleGrid(triangles, cutter.radius), cutter, deflection, lift, box, faces, owner,
                 meter or WorkMeter())


def _check_tool(tool) -> Tool:
    if not isinstance(tool, Tool):
        raise SurfmodError(f"tool: expected a surfmod Tool, got {type(tool).__name__}")
    return tool


def drop_cutter(obj, tool: Tool, xy, *, tolerance: float | None = None, exact: bool = False):
    """Tool-tip heights ``(N,)`` and contact points ``(N, 3)`` of ``tool`` dropped onto
    every face of ``obj`` at the (x, y) locations ``xy`` ``(N, 2)`` (NaN where the tool
    touches nothing).  The faces are meshed to 40 % of ``tolerance`` (default
    ``radius / 1000``); heights are exact for that mesh.

    ``exact=True`` polishes each height on the exact face the tool rests on
    (:mod:`surfmod.cam.toolpath_exact`: Newton on the face's own evaluator, inside its
    trim: the ball's centre, a flat end's rim on a sloped face or its bottom on a
    summit), so it is exact to rounding on the B-rep, contact points included; where the
    tool rests on an edge or a vertex of the mesh the mesh height is kept, lifted as
    above.  Every other face under the tool is polished too and the highest height kept:
    the mesh can pick the wrong face where another stands within its deviation (a ball
    at the foot of a bump beside the floor).

    >>> import surfmod as sm
    >>> from surfmod.cam.toolpath import drop_cutter
    >>> z, contact = drop_cutter(sm.plane((0, 0, 2), (4, 0, 2), (0, 4, 2)), sm.Tool("ball", 1.0), [[1.0, 1.0]])
    >>> z.tolist(), contact.tolist()
    ([2.0], [[1.0, 1.0, 2.0]])
    """
    tool = _check_tool(tool)
    cl = checks.finite_array(xy, "xy", ndim=2, last=2)
    tolerance = tool.radius / 1000 if tolerance is None else checks.positive(tolerance, "tolerance")
    part = meshed_part(obj, tool.cutter, tolerance)
    z, contacts, touched = drop(part.grid, part.cutter, cl, contacts=True, triangles=True)
    z = z + part.lift
    if exact:
        z, contacts, polished = exact_heights(part.faces, part.owner, cl, z, contacts, touched, tool.radius,
                                              tool.corner)
        _rival_faces(part, tool, cl, z, contacts, np.flatnonzero(polished), part.owner[touched[polished]])
    return z, contacts


def _rival_faces(part: MeshedPart, tool: Tool, xy: np.ndarray, z, contacts, rows: np.ndarray, chosen: np.ndarray):
    """Raise, in place, the heights ``z`` polished at ``xy[rows]`` on the faces ``chosen``
    where another face under the tool is higher on the exact B-rep (a ball at the foot of a
    bump beside the floor, where the mesh saw the floor higher: a steep face's mesh can
    stand lower by its deviation over the normal's vertical part): each such face's exact
    height, its lifted mesh height where it cannot be polished."""
    tri = part.grid.triangles
    for face in np.unique(part.owner):
        mine = part.owner == face
        lo, hi = tri[mine, :, :2].min(axis=(0, 1)) - tool.radius, tri[mine, :, :2].max(axis=(0, 1)) + tool.radius
        at = rows[np.all((xy[rows] >= lo) & (xy[rows] <= hi), axis=1) & (chosen != face)]
        if not at.size:
            continue
        h, touch = drop(TriangleGrid(tri[mine], tool.radius), part.cutter, xy[at], contacts=True)
        rival = np.isfinite(h)
        if not rival.any():
            continue
        at, h, touch = at[rival], h[rival], touch[rival]
        exact, contact, on = polish(from_face(part.faces[face]), xy[at], touch, tool.radius, tool.corner)
        height = np.where(on, exact, h + part.lift)
        higher = height > z[at]
        z[at[higher]] = height[higher]
        contacts[at[higher]] = np.where(on[higher, None], contact[higher], touch[higher])


def finish_settings(tool: Tool, stepover, scallop, direction: str) -> tuple[float, float]:
    """``(stepover, tolerance)`` of a finishing by ``tool`` given ``stepover`` or
    ``scallop`` (the stepover that leaves it on flat ground), checked against the tool;
    ``tolerance`` is the default depth no move may cut: a tenth of the cusp the stepover
    leaves, or ``radius / 100`` where it leaves none.  :func:`toolpath` and the job's
    finishing both call it, so a bad scallop is refused before any work."""
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
    if direction not in ("x", "y"):
        raise SurfmodError(f"direction: expected 'x' or 'y', got {direction!r}")
    cusp = tool.scallop_for_stepover(stepover)
    return stepover, cusp / 10 if cusp > 0 else tool.radius / 100


def _drop_repeats(points: np.ndarray, index: np.ndarray):
    """Remove locations equal to their predecessor (zero-length moves of staircases)."""
    keep = np.r_[True, np.any(points[1:] != points[:-1], axis=1)]
    return points[keep], index[keep]


def toolpath(obj, tool: Tool, stepover: float | None = None, *, scallop: float | None = None,
             step: float | None = None, direction: str = "x", bounds=None, tolerance: float | None = None,
             progress: bool = False, max_points: int = MAX_LOCATIONS, max_work: int = MAX_WORK) -> Toolpath:
    """Zig-zag drop-cutter finishing path of ``tool`` over a part, every move gouge-checked.

    ``obj``: a surfmod surface (or list of them), a build123d shape or a STEP path; all its
    faces count (walls and trimmed faces included; the shank is as wide as the tool).
    Give ``stepover`` (distance between passes, at most the tool diameter) or ``scallop``
    (cusp height on flat ground for a ball cutter, stepover = 2·sqrt(2rh − h²)).  ``step``
    is the spacing of locations along a pass (default ``radius / 4``); passes run along
    ``direction`` ``"x"`` or ``"y"`` over the part's (x, y) bounding box or ``bounds =
    ((xmin, ymin), (xmax, ymax))``.  ``tolerance``: the depth no move may cut (default a
    tenth of the scallop height, or ``radius / 100`` when the stepover leaves none); a
    path that cannot be made to respect it raises ``SurfmodError``.  ``progress`` shows a
    tqdm bar of the drop-cutter's triangle tests, the stage beside it.  More than
    ``max_points`` cutter locations (estimated from the bounds, stepover and step before
    the part is meshed or anything is allocated) are refused; raise ``max_points`` to
    allow them.  The work is bounded too, each bound checked before its work starts: a
    mesh of more than ``MAX_TRIANGLES`` by the curvature estimate, or a tolerance below
    the floor of the part's size (``tolerance:``), and more than ``max_work`` triangle
    tests of the drop-cutter (about a minute of one core), estimated from the raster on
    the mesh and charged again before each round of refinement (``max_work:``).

    >>> import surfmod as sm, numpy as np
    >>> s = sm.plane((0, 0, 1), (10, 0, 1), (0, 10, 1))
    >>> tp = sm.toolpath(s, sm.Tool("ball", 2.0), scallop=0.05)
    >>> bool(tp.stepover <= 2 * np.sqrt(2 * 2 * 0.05 - 0.05 ** 2)), float(np.abs(tp.points[:, 2] - 1).max()) < 1e-12
    (True, True)
    """
    tool = _check_tool(tool)
    stepover, default = finish_settings(tool, stepover, scallop, direction)
    step = tool.radius / 4 if step is None else checks.positive(step, "step")
    tolerance = default if tolerance is None else checks.positive(tolerance, "tolerance")
    if bounds is not None:
        box = checks.finite_array(bounds, "bounds")
        if box.shape != (2, 2) or np.any(box[1] < box[0]):
            raise SurfmodError(f"bounds: expected ((xmin, ymin), (xmax, ymax)), got {box.tolist()}")
    def estimate(lo, hi):
        a, b = (0, 1) if direction == "x" else (1, 0)
        passes = float(hi[b] - lo[b]) / stepover + 2
        along = float(hi[a] - lo[a]) / step + 2
        checks.work(passes * along + passes * stepover / step, max_points, "max_points",
                    f"the raster of {passes:,.0f} passes x {along:,.0f} locations (use a larger step or stepover)")

    shape = to_shape(obj, "obj")
    if bounds is None:  # the shape's box (a little larger than the mesh's) sizes the raster up front
        from ..occ.properties import bounding_box

        outer = bounding_box(shape)
        estimate(outer[0, :2], outer[1, :2])
    else:
        estimate(box[0], box[1])
    max_work = checks.count(max_work, "max_work")
    # the bar counts triangle tests (estimated once the mesh is known), so it moves with
    # every round of the refinement, the stage it is in beside it
    with tqdm(total=1, desc="toolpath", unit=" tests", unit_scale=True, disable=not progress) as bar:
        bar.set_postfix_str("meshing")
        meter = WorkMeter(max_work, bar)
        part = meshed_part(shape, tool.cutter, tolerance, meter)
        path = raster_path(part, tool, stepover, step, direction, None if bounds is None else box, tolerance,
                           bar, meter=meter)
        # the mesh's triangles can miss where a face leaves them between the measured
        # samples: the moves are held against points of the exact faces too, and lifted there
        bar.set_postfix_str("against the exact faces")
        points, lift = lift_gouges(shape, path.points, tool.cutter, tolerance)
    if not lift.any():
        return path
    return replace(path, points=checks.frozen(points), lifted=max(path.lifted, float(lift.max())))


def raster_path(part: MeshedPart, tool: Tool, stepover: float, step: float, direction: str, bounds, tolerance: float,
                bar=None, across=None, meter: WorkMeter | None = None) -> Toolpath:
    """The verified zig-zag :class:`Toolpath` of ``tool`` over an already meshed ``part``
    (:func:`toolpath` after its checks; ``bounds`` ``((xmin, ymin), (xmax, ymax))`` or None
    for the part's box; ``bar`` a tqdm bar counting triangle tests; ``across``: the passes'
    cross positions instead of ``stepover``; ``meter``: the work bound, checked up front)."""
    stage = bar.set_postfix_str if bar is not None else (lambda text: None)
    lo, hi = (part.box[0, :2], part.box[1, :2]) if bounds is None else (np.asarray(bounds[0]), np.asarray(bounds[1]))
    xy, index, across = raster(lo, hi, stepover, step, direction, across)
    if meter is not None:
        first = part.grid.entries(xy)
        meter.refuse(NOMINAL_DROPS * first,
                     f"the drop-cutter over {len(xy):,} locations of {first / max(len(xy), 1):,.0f} triangle tests "
                     f"each, {NOMINAL_DROPS} drops a location at the least (a larger tolerance, scallop or step)")
        if bar is not None:
            bar.total = meter.used + NOMINAL_DROPS * first
    stage("dropping")
    z = part.height(xy)
    if np.isnan(z).all():
        raise SurfmodError("bounds: the tool touches no face inside these bounds")
    floor = float(np.nanmin(z))  # where the tool touches nothing it stays at the lowest level
    # the drop height under each point rides along as a fourth column: the final check
    # takes it instead of dropping at every point again
    points = np.column_stack([xy, np.where(np.isnan(z), floor, z), np.where(np.isnan(z), -np.inf, z)])
    stage("refining")
    allowed = tolerance - part.deflection + part.lift
    if allowed <= 0:
        raise SurfmodError(f"tolerance: {tolerance:.3g} is below the part's mesh deflection {part.deflection:.3g}")
    min_length = min(tolerance, step / 64)
    for _ in range(2):  # the refinement makes short steep moves at walls: staircase them too
        points, index = staircase_steep(points, index)
        points, index = refine_moves(part.height, points, index, REFINE_SHARE * allowed, min_length, floor)
    points, index = _drop_repeats(points, index)
    stage("checking every move")
    depth = move_gouge(part.height, points)
    if depth.max() > allowed:
        # repair what the verdict's own sample points found, then judge again
        points, index = refine_moves(part.height, points, index, REFINE_SHARE * allowed, min_length, floor,
                                     centred=True)
        points, index = _drop_repeats(points, index)
        depth = move_gouge(part.height, points)
    lifted = 0.0
    if len(depth) and depth.max() > allowed:
        # the refinement could not follow the part here (walls meeting at a sliver of a
        # face, say): lift those moves, which leaves material but never cuts
        points, lift, depth = lift_moves(part.height, points, depth, REFINE_SHARE * allowed)
        lifted = float(lift.max())
    points = points[:, :3]
    gouge = float(depth.max()) if len(depth) else 0.0
    if gouge > allowed:
        worst = int(np.argmax(depth))
        raise NoSafePathError(
            f"toolpath: no safe path: move {worst + 1} still cuts {gouge + part.deflection - part.lift:.3g} "
            f"deep, more than the tolerance {tolerance:.3g}")
    if meter is not None:
        meter.charge(part.grid.entries(points[:, :2]), "the contacts")
    _, contacts = drop(part.grid, part.cutter, points[:, :2], contacts=True)
    if bar is not None and meter is not None:
        bar.total = bar.n
    stage("done")
    actual = float(np.diff(across).max()) if len(across) > 1 else 0.0
    return Toolpath(checks.frozen(points), checks.frozen(contacts), index, tool, actual, step,
                    tool.scallop_for_stepover(actual), direction, gouge - part.lift, tolerance, part.deflection, lifted)
