"""Cross-section views: planar sections of a part as curves, in 3-D and in the plane's frame.

The same concept as :mod:`surfmod.cli.section` (the ``surfmod section`` command over this);
the OCCT section it reads is :mod:`surfmod.occ.booleans`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from .. import checks
from ..atomic import atomic_path, target_path
from ..construct.conics import Conic
from ..construct.curves import Line
from ..construct.from_edge import from_edge
from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve
from ..readback import read_curve
from ..inputs import to_shape


def section_axes(normal: np.ndarray, x_axis=None) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal in-plane axes ``(x, y)`` with ``x × y = normal``.

    Without ``x_axis`` the x axis is the projection of the global X axis (or of Y when
    the normal is close to X): a plane with normal +Z gets the global X/Y axes.
    """
    if x_axis is None:
        helper = np.array([1.0, 0, 0]) if abs(normal[0]) < 0.9 else np.array([0, 1.0, 0])
    else:
        helper = checks.direction(x_axis, "x_axis")
    x = helper - np.dot(helper, normal) * normal
    if np.linalg.norm(x) < 1e-9:
        raise SurfmodError("x_axis: must not be parallel to plane_normal")
    x /= np.linalg.norm(x)
    return x, np.cross(normal, x)


#: the most points :meth:`Section.polylines_2d` discretizes the section edges into (estimated
#: first): OCCT's GCPnts takes ~20 us a point, so about 4 s
MAX_CHORD_POINTS = 200_000


def chord_points(polylines, tolerance: float) -> float:
    """Points a chordal ``tolerance`` needs along curves sampled as ``polylines``: a chord
    ``h`` on curvature ``k`` sags ``k h^2 / 8``, so a stretch ``h`` turning by ``theta``
    (curvature ``theta / h``) needs ``sqrt(theta h / (8 tolerance))`` chords; exact for a
    circle sampled evenly.

    >>> t = np.linspace(0, 2 * np.pi, 65)
    >>> exact = 2 * np.pi * np.sqrt(1 / 8e-6)  # a unit circle's chords, plus the 65 samples
    >>> bool(exact < chord_points([np.c_[np.cos(t), np.sin(t), 0 * t]], 1e-6) < exact + 65)
    True
    """
    total = 0.0
    for p in polylines:
        seg = np.diff(np.asarray(p, float), axis=0)
        h = np.linalg.norm(seg, axis=1)
        seg, h = seg[h > 0], h[h > 0]
        total += len(p)
        if len(seg) < 2:
            continue
        cos = np.einsum("ij,ij->i", seg[:-1], seg[1:]) / (h[:-1] * h[1:])
        theta = np.arccos(np.clip(cos, -1.0, 1.0))
        total += float(np.sqrt(theta * 0.5 * (h[:-1] + h[1:]) / (8 * tolerance)).sum())
    return total


@dataclass(frozen=True)
class Section:
    """Section curves of a part by a plane.

    ``wires`` are build123d ``Wire``s (OCCT's section edges chained end to end);
    ``polylines`` the same curves sampled by the NumPy evaluator (each edge read back
    exactly with :func:`surfmod.from_edge`, ``samples`` points an edge), one ``(N, 3)``
    array per wire, computed on first use; ``closed`` says which wires close up.  The
    plane frame is ``origin`` with axes ``x_axis``, ``y_axis`` and ``normal``;
    :meth:`polylines_2d` gives the curves in it.
    An empty section (the plane misses the part) has no wires.  ``faces_on`` are the
    indices of the planar faces lying in the plane: their outlines are part of the
    section, as a CAD system draws it.  ``faces_skipped`` (``{index: reason}``, only
    with ``section(..., partial=True)``) are the faces OCCT could not intersect: their
    curves are missing.

    >>> import surfmod as sm, build123d as bd
    >>> sec = sm.section(bd.Box(2, 2, 2), (0, 0, 0), (0, 0, 1))
    >>> len(sec.wires), sec.closed
    (1, [True])
    """

    origin: np.ndarray
    normal: np.ndarray
    x_axis: np.ndarray
    y_axis: np.ndarray
    wires: list = field(repr=False)
    closed: list
    samples: int = field(default=64, repr=False)
    faces_on: tuple = ()
    faces_skipped: dict = field(default_factory=dict)

    @cached_property
    def polylines(self) -> list[np.ndarray]:
        from ..occ.sample import wire_edges

        def sampled(edge):  # from_edge follows the edge's orientation
            curve = from_edge(edge)
            return curve.points(np.linspace(*curve.domain, self.samples))

        return [checks.frozen(_chained([sampled(e) for e in wire_edges(w)])) for w in self.wires]

    @property
    def empty(self) -> bool:
        return not self.wires

    @property
    def length(self) -> float:
        """Total length of the section curves (OCCT edge lengths)."""
        return float(sum(w.length for w in self.wires))

    def to_plane(self, points) -> np.ndarray:
        """3-D points ``(..., 3)`` in the plane frame ``(..., 2)``."""
        axes = np.stack([self.x_axis, self.y_axis], axis=1)
        return (np.asarray(points, dtype=float) - self.origin) @ axes

    def polylines_2d(self, tolerance: float | None = None) -> list[np.ndarray]:
        """The curves in the plane frame, ``(N, 2)`` each: the stored polylines, or with
        ``tolerance`` points whose chords stay within ``tolerance`` of the exact edges
        (OCCT ``GCPnts_QuasiUniformDeflection``)."""
        if tolerance is None:
            return [self.to_plane(p) for p in self.polylines]
        from ..occ.sample import edge_points, wire_edges

        pts = np.concatenate(self.polylines) if self.polylines else np.zeros((0, 3))
        size = float(np.linalg.norm(np.ptp(pts, axis=0))) if len(pts) else 0.0
        tol = checks.tolerance(tolerance, "tolerance", size)
        need = chord_points(self.polylines, tol)
        if need > MAX_CHORD_POINTS:  # GCPnts takes ~20 us a point: 1e-12 of a sphere's section ran 70 s
            raise SurfmodError(f"tolerance: {tol:g} would need about {need:,.0f} points along the section, above "
                               f"{MAX_CHORD_POINTS:,}")
        return [self.to_plane(_chained([edge_points(e, tol) for e in wire_edges(w)])) for w in self.wires]

    def entities_2d(self) -> list[list[tuple]]:
        """The exact section curves in the plane frame, per wire a list of
        ``("line", p0, p1)``, ``("arc", center, radius, start_deg, end_deg)`` (counter-
        clockwise from start to end), ``("circle", center, radius)`` or
        ``("spline", degree, control_points (N, 2), knots, weights or None)``; B-splines
        keep their knots and weights, every other curve type is converted to its exact
        B-spline form."""
        from ..occ.sample import wire_edges

        return [[_edge_entity(self, e) for e in wire_edges(w)] for w in self.wires]

    def areas(self) -> np.ndarray:
        """Signed areas (shoelace, in the plane frame) of the closed curves; 0 for open ones."""
        out = []
        for q, c in zip(self.polylines_2d(), self.closed):
            out.append(0.5 * float(np.sum(q[:-1, 0] * q[1:, 1] - q[1:, 0] * q[:-1, 1])) if c else 0.0)
        return np.array(out)

    def preview(self, path, *, dpi: int = 120) -> None:
        """A PNG drawing of the section in the plane frame (matplotlib, atomic write)."""
        # a local Agg canvas: the caller's pyplot backend is left alone
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        target = target_path(path, "path", (".png",))
        fig = Figure(figsize=(5, 5))
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        for q in self.polylines_2d():
            ax.plot(q[:, 0], q[:, 1], "-", lw=1.2, color="tab:blue")
        ax.set_aspect("equal")
        ax.set_xlabel("plane x")
        ax.set_ylabel("plane y")
        o, n = self.origin, self.normal
        ax.set_title(f"section at ({o[0]:.4g}, {o[1]:.4g}, {o[2]:.4g}) n=({n[0]:.3g}, {n[1]:.3g}, {n[2]:.3g})", fontsize=9)
        ax.grid(True, lw=0.3)
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format="png", dpi=dpi)

    def __str__(self) -> str:
        if self.empty:
            return "section: empty (the plane misses the part)"
        on = (f"; the plane lies on planar face(s) {list(self.faces_on)}: their outline included"
              if self.faces_on else "")
        skipped = (f"; {len(self.faces_skipped)} face(s) OCCT could not intersect left out: "
                   f"{sorted(self.faces_skipped)}" if self.faces_skipped else "")
        return (f"section: {len(self.wires)} curve(s), {sum(self.closed)} closed, total length {self.length:.9g}"
                f"{on}{skipped}")


def _chained(pieces: list[np.ndarray]) -> np.ndarray:
    """One polyline from a wire's edge polylines, each starting where the one before ends
    (the shared point kept once)."""
    return np.concatenate([p if i == 0 else p[1:] for i, p in enumerate(pieces)])


def _edge_entity(sec: Section, edge) -> tuple:
    """One section edge as an exact 2-D entity in the section's plane frame."""
    from ..occ.geom import read_bspline_curve
    from ..occ.topo import curve_of_edge, shape_bspline

    geom, t0, t1 = curve_of_edge(edge)
    curve = read_curve(geom, (t0, t1))
    if isinstance(curve, Line):
        p = sec.to_plane(curve.points(np.array([t0, t1])))
        return ("line", p[0], p[1])
    if isinstance(curve, Conic) and curve.a == curve.b and abs(abs(float(curve.normal @ sec.normal)) - 1.0) < 1e-9:
        center, r = sec.to_plane(curve.center), curve.a
        if t1 - t0 >= 2 * np.pi * (1 - 1e-12):
            return ("circle", center, r)
        ends = sec.to_plane(curve.points(np.array([t0, t1]))) - center
        a0, a1 = np.degrees(np.arctan2(ends[:, 1], ends[:, 0]))
        # the conic turns counter-clockwise in the plane frame when its normal is the plane's
        return ("arc", center, r, a0, a1) if float(curve.normal @ sec.normal) > 0 else ("arc", center, r, a1, a0)
    data = read_bspline_curve(shape_bspline(edge))
    c = BSplineCurve(data["points"], data["degree"], data["knots"], data["weights"])
    return ("spline", c.degree, sec.to_plane(c.control_points), np.asarray(c.knots), None if c.weights is None else np.asarray(c.weights))


def section(obj, plane_origin, plane_normal, *, samples: int = 64, x_axis=None, partial: bool = False) -> Section:
    """Planar section of a part (or of surfaces): curves where the plane cuts it.

    ``obj``: a build123d shape, surfmod surface(s) or a STEP path.  A plane that misses
    the part gives an empty :class:`Section`; a plane lying on planar faces of the part
    gives their outlines (``BRepAlgoAPI_Section`` returns the boundary of the common
    part), with the curves where it crosses the other faces, and names the faces in
    ``faces_on``.  When OCCT cannot section the whole part it raises ``SurfmodError``;
    with ``partial=True`` the part is then sectioned face by face, and the faces OCCT
    cannot intersect are left out and named in ``faces_skipped``.

    >>> import surfmod as sm, build123d as bd
    >>> s = sm.section(bd.Sphere(2), (0, 0, 1), (0, 0, 1))
    >>> len(s.wires), s.closed, round(s.length, 12) == round(2 * 3.141592653589793 * 3 ** 0.5, 12)
    (1, [True], True)
    >>> top = sm.section(bd.Box(2, 2, 2) - bd.Cylinder(0.5, 3), (0, 0, 1), (0, 0, 1))
    >>> top.faces_on, round(top.length, 12) == round(8 + 3.141592653589793, 12)
    ((2,), True)
    """
    from ..occ.properties import bounding_box
    from ..occ.booleans import planar_faces_on, wires_of

    origin = checks.point(plane_origin, "plane_origin")
    normal = checks.direction(plane_normal, "plane_normal")
    samples = checks.count(samples, "samples", minimum=2)
    xa, ya = section_axes(normal, x_axis)
    shape = to_shape(obj, "obj")
    # only a length scale for the on-face test: OCCT's quick box, not the optimal one
    # (which costs more than the section itself on B-spline parts)
    box = bounding_box(shape, optimal=False)
    tol = 1e-9 * max(1.0, float(np.linalg.norm(box[1] - box[0])))
    on = tuple(planar_faces_on(shape, origin, normal, tol))
    skipped: dict = {}
    wires = wires_of(_section_edges(shape, origin, normal, skipped if partial else None))
    return Section(checks.frozen(origin), checks.frozen(normal), checks.frozen(xa), checks.frozen(ya),
                   wires, [bool(w.is_closed) for w in wires], samples, on, skipped)


def _section_edges(shape, origin, normal, skipped: dict | None) -> list:
    """The edges of ``shape``'s section by the plane.  When OCCT cannot section the whole
    shape and ``skipped`` is a dict, the shape is sectioned face by face (one Boolean a
    face): the faces OCCT cannot intersect go into ``skipped`` as ``{index: reason}`` and
    the others' edges are returned; without ``skipped``, or when no face can be
    sectioned, the failure is raised."""
    from ..occ import booleans
    from ..occ.topo import faces_of

    try:
        return booleans.cut_edges(shape, origin, normal)
    except SurfmodError as whole:
        if skipped is None:
            raise
        failure = whole
    faces, edges, lost = faces_of(shape), [], {}
    for i, face in enumerate(faces):
        try:
            edges.extend(booleans.cut_edges(face, origin, normal))
        except SurfmodError as exc:
            lost[i] = " ".join(str(exc).split())
    if len(lost) == len(faces):
        raise failure
    skipped.update(lost)
    return edges
