"""Headless shaded pictures (PNG) of surfaces, curves, faces, meshes, shapes and tool paths
(matplotlib's Agg backend, no display server).

:func:`render` writes a PNG file; :func:`png_bytes` returns a small one in memory, which is
what the ``_repr_png_`` of surfmod's objects calls:

>>> import surfmod as sm
>>> sm.sphere(1.0)._repr_png_().startswith(PNG_SIGNATURE)
True

Objects of the layers above this one (tool paths, machining jobs) are drawn through one
protocol: a method ``drawing()`` returning a :class:`Drawing` or a list of them.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import checks
from ..atomic import atomic_path, target_path
from ..curve import Curve
from ..errors import SurfmodError
from ..readback import TrimmedFace
from ..surface import Surface, model_size
from .facemesh import brepmesh, concatenated
from .figures import shape_diagonal
from .grid import mesh as grid_mesh
from .isocurves import isocurves as iso
from .polymesh import Mesh
from .tessellate import tessellate_surface

#: Display tessellation: chordal tolerance as a fraction of the object's size.
DISPLAY_TOLERANCE = 0.004
#: Above this many triangles a display mesh falls back to a grid (keeps a PNG < 2 s).
DISPLAY_TRIANGLES = 12000
#: Meshes and shapes finer than this are simplified for a picture (matplotlib draws ~50k/s).
SHOWN_TRIANGLES = 60000
LIGHT = np.array([0.4, -0.5, 0.77])
#: The eight bytes every PNG file starts with.
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: Picture in memory (notebooks): pixel size, and coarser tessellation than a file's.
PNG_SIZE = (400, 300)
PNG_TOLERANCE = 0.008
PNG_TRIANGLES = 5000
#: Bounds of a picture's size in pixels, and of what one picture draws.
MIN_PIXELS, MAX_PIXELS = 16, 4096
MAX_SEGMENTS = 40000
#: Curves are drawn as polylines of this many points.
CURVE_SAMPLES = 200
LINE_COLOR = (0.1, 0.1, 0.15, 0.8)
NET_COLOR = (0.85, 0.2, 0.1, 0.9)


@dataclass(frozen=True)
class Drawing:
    """What one object adds to a picture: a shaded ``mesh`` (or ``None``), ``lines`` (a
    list of ``(k, 3)`` polylines) drawn in ``line_color`` over it, and an optional control
    ``net`` ``(m, n, 3)``.

    Objects above the meshing layer (``sm.Toolpath``, machining jobs) are pictured by
    :func:`render` and :func:`png_bytes` through a method ``drawing()`` returning one
    ``Drawing`` or a list of them.

    >>> import numpy as np
    >>> d = Drawing(lines=[np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.]])], line_color=(0, 0, 1, 1))
    >>> png_bytes(d).startswith(PNG_SIGNATURE)
    True
    """

    mesh: Mesh | None = None
    lines: tuple | list = ()
    line_color: tuple = LINE_COLOR
    line_width: float = 0.6
    net: np.ndarray | None = None


def _surface_mesh(s, fraction: float = DISPLAY_TOLERANCE, budget: int = DISPLAY_TRIANGLES) -> Mesh:
    size = model_size(s, samples=17)
    try:
        m = tessellate_surface(s, max(fraction * size, 1e-12), budget)
        if len(m.faces) <= budget:
            return m
    except SurfmodError:
        pass
    side = max(int(np.sqrt(budget / 2)), 8)
    return grid_mesh(s, side, side)


def display_mesh(m: Mesh, budget: int) -> Mesh:
    """``m`` as triangles, at most about ``budget`` of them: a finer mesh is simplified by
    vertex clustering (Rossignac–Borrel: vertices merged per cell of a grid over the
    bounding box, collapsed triangles dropped), halving the cell count per axis until it
    fits (at most 10 rounds).  A picture needs no more triangles than it has pixels.

    >>> import surfmod as sm
    >>> fine = sm.tessellate(sm.sphere(1.0), 1e-4)
    >>> len(fine.faces) > 20000, len(display_mesh(fine, 5000).faces) <= 5000
    (True, True)
    """
    tri = m.triangles()
    if len(tri) <= budget:
        return Mesh(m.vertices, tri, dict(m.info))
    lo, hi = m.vertices.min(axis=0), m.vertices.max(axis=0)
    span = np.maximum(hi - lo, 1e-300)
    cells = int(np.sqrt(budget))  # a closed surface crosses about 2 * cells^2 cells
    for _ in range(10):
        key = np.minimum(((m.vertices - lo) / span * cells).astype(np.int64), cells - 1)
        flat = (key[:, 0] * cells + key[:, 1]) * cells + key[:, 2]
        ids, cluster = np.unique(flat, return_inverse=True)
        t = cluster.ravel()[tri]
        t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
        t = np.unique(np.sort(t, axis=1), axis=0) if len(t) > budget else t
        if len(t) <= budget or cells <= 2:
            break
        cells = max(cells // 2, 2)
    centre = np.zeros((len(ids), 3))
    np.add.at(centre, cluster.ravel(), m.vertices)
    centre /= np.bincount(cluster.ravel(), minlength=len(ids))[:, None]
    return Mesh(centre, t[:budget], dict(m.info))


def _shape_mesh(shape, fraction: float = DISPLAY_TOLERANCE) -> Mesh:
    fms = brepmesh(shape, max(fraction * shape_diagonal(shape), 1e-9), 0.5)
    if not fms:  # faces all left untriangulated by BRepMesh (brepmesh skips them)
        raise SurfmodError("objects: the shape has no faces to draw")
    nodes, triangles, _, _ = concatenated(fms)
    return Mesh(nodes, triangles)


def _shape_edges(shape, samples: int = 48) -> list[np.ndarray]:
    from ..occ.sample import sample_curve
    from ..occ.topo import curve_of_edge

    out = []
    for e in shape.edges():
        try:
            curve, t0, t1 = curve_of_edge(e)
        except SurfmodError:
            continue
        out.append(sample_curve(curve, t0, t1, samples))
    return out


def _curve_line(c: Curve, samples: int = CURVE_SAMPLES) -> np.ndarray:
    """A polyline of ``c`` through its breaks (corners of a degree-1 B-spline stay sharp)."""
    t0, t1 = c.domain
    t = np.union1d(np.linspace(t0, t1, samples), np.clip(c.breaks, t0, t1))
    return c.points(t)


@dataclass(frozen=True)
class _Detail:
    """How finely a picture draws: tessellation tolerance (fraction of the size), the
    triangle budget of a surface's tessellation, and the most triangles of a mesh or shape
    drawn (finer ones are simplified by :func:`display_mesh`)."""

    fraction: float = DISPLAY_TOLERANCE
    triangles: int = DISPLAY_TRIANGLES
    shown: int = SHOWN_TRIANGLES


def _drawings(obj, isocurves: bool, control_net: bool, iso_count, eye, detail: _Detail) -> list[Drawing]:
    """The :class:`Drawing` s of one object."""
    if isinstance(obj, Drawing):
        return [obj]
    if isinstance(obj, Mesh):
        return [Drawing(display_mesh(obj, detail.shown))]
    if isinstance(obj, TrimmedFace):
        # a face read back is drawn inside its trim, with its boundary edges
        face = obj.face()
        return [Drawing(display_mesh(_shape_mesh(face, detail.fraction), detail.shown),
                        _shape_edges(face) if isocurves else [])]
    if isinstance(obj, Surface):
        m = _surface_mesh(obj, detail.fraction, detail.triangles)
        lines = _iso_lines(obj, m, iso_count, eye) if isocurves else []
        net = None
        if control_net and getattr(obj, "control_points", None) is not None:
            net = np.asarray(obj.control_points)
        return [Drawing(m, lines, net=net)]
    if isinstance(obj, Curve):
        return [Drawing(None, [_curve_line(obj)], line_color=(0.1, 0.25, 0.6, 1.0), line_width=1.2)]
    drawing = getattr(obj, "drawing", None)
    if callable(drawing):
        out = drawing()
        out = list(out) if isinstance(out, (list, tuple)) else [out]
        if not out or not all(isinstance(d, Drawing) for d in out):
            raise SurfmodError(f"objects: {type(obj).__name__}.drawing() must return Drawing objects")
        return out
    shape = getattr(obj, "wrapped", None)
    if shape is None or not hasattr(obj, "edges"):
        raise SurfmodError(
            f"objects: cannot render {type(obj).__name__} "
            "(expected a surface, curve, Mesh, tool path or build123d shape)"
        )
    m = display_mesh(_shape_mesh(obj, detail.fraction), detail.shown)
    return [Drawing(m, _shape_edges(obj) if isocurves else [])]


def _iso_lines(s, m: Mesh, iso_count, eye, samples: int = 80) -> list[np.ndarray]:
    """Iso-curve polylines; on a surface that closes on itself (sphere, torus, tube) the
    parts facing away from the viewer are dropped, since lines are drawn over the shading."""
    fam = iso(s, *iso_count)
    ul, vl = fam.polylines(samples)
    closed = any(m.info.get("closed", (False, False)))
    if not closed:
        return list(ul) + list(vl)
    tri = m.vertices[m.triangles()]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()
    sign = 1.0 if volume >= 0 else -1.0
    (u0, u1), (v0, v1) = s.domain
    t_u, t_v = np.linspace(u0, u1, samples), np.linspace(v0, v1, samples)
    out = []
    for pts, uu, vv in (
        (ul, *np.meshgrid(fam.u_values, t_v, indexing="ij")),
        (vl, *np.meshgrid(t_u, fam.v_values, indexing="xy")),
    ):
        if len(pts) == 0:
            continue
        facing = sign * (s.normals(uu, vv) @ eye) > -0.05
        seg = np.stack([pts[:, :-1], pts[:, 1:]], axis=2)
        keep = facing[:, :-1] & facing[:, 1:]
        out.extend(list(seg[keep]))
    return out


def shade(triangles: np.ndarray, color, light=LIGHT) -> np.ndarray:
    """RGBA per triangle: ambient 0.35 + diffuse 0.65 |n . l| (two-sided Lambert).

    >>> shade(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float), (1, 1, 1), (0, 0, 1))[0, :3]
    array([1., 1., 1.])
    """
    n = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = n / np.where(norm > 0, norm, 1.0)
    light = np.asarray(light, float)
    lam = np.abs(n @ (light / np.linalg.norm(light)))
    rgb = np.clip(np.asarray(color, float)[None, :3] * (0.35 + 0.65 * lam)[:, None], 0, 1)
    return np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1)


def _items(objects) -> list:
    items = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if not items:
        raise SurfmodError("objects: nothing to render")
    return items


def _segments(lines, limit: int) -> list[np.ndarray]:
    """Polylines as at most about ``limit`` segments in all: a longer polyline keeps every
    k-th point (and its last), as a picture cannot show finer steps anyway."""
    lines = [np.asarray(p, float) for p in lines if len(p) > 1]
    total = sum(len(p) - 1 for p in lines)
    if total <= limit:
        return lines
    k = int(np.ceil(total / limit))
    return [np.concatenate([p[::k], p[-1:]]) if len(p) > k else p[[0, -1]] for p in lines]


def _figure(items, *, isocurves, control_net, iso_count, elev, azim, figsize, dpi, rgb, title, detail):
    """The matplotlib ``Figure`` (on a local Agg canvas) showing ``items``."""
    # A local Agg canvas: the caller's pyplot backend is left alone.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    fig = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # curves and nets are drawn over the shading
    e, a = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    drawings = [d for obj in items for d in _drawings(obj, isocurves, control_net, iso_count, eye, detail)]
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)

    def grow(points):
        nonlocal lo, hi
        if len(points):
            lo, hi = np.minimum(lo, points.min(axis=0)), np.maximum(hi, points.max(axis=0))

    for d in drawings:
        if d.mesh is not None and len(d.mesh.faces):
            m = d.mesh.triangulated()
            tri = m.vertices[m.faces]
            grow(m.vertices)
            fc = shade(tri, rgb)  # edges in the face colour hide anti-aliasing seams
            ax.add_collection3d(Poly3DCollection(tri, facecolors=fc, edgecolors=fc, linewidths=0.3, zorder=1))
        lines = _segments(d.lines, MAX_SEGMENTS)
        if lines:
            for p in lines:
                grow(p)
            ax.add_collection3d(Line3DCollection(lines, colors=d.line_color, linewidths=d.line_width, zorder=2))
        if d.net is not None:
            net = np.asarray(d.net, float)
            segs = list(net) + list(net.transpose(1, 0, 2))
            ax.add_collection3d(Line3DCollection(segs, colors=NET_COLOR, linewidths=0.8, zorder=3))
            flat = net.reshape(-1, 3)
            ax.scatter(flat[:, 0], flat[:, 1], flat[:, 2], color=NET_COLOR[:3], s=6, depthshade=False, zorder=4)
            grow(flat)
    if not np.all(np.isfinite(lo)):
        raise SurfmodError("objects: nothing to draw (no triangles, lines or points)")
    # true proportions, but flat objects keep a third of the largest extent in height
    centre = (lo + hi) / 2
    extent = np.maximum(hi - lo, max(float(np.max(hi - lo)), 1e-9) / 3)
    for axis, c, e in zip("xyz", centre, extent):
        getattr(ax, f"set_{axis}lim")(c - e / 2, c + e / 2)
    ax.set_box_aspect(tuple(extent), zoom=1.0)
    ax.view_init(elev=elev, azim=azim)
    ax.set_axis_off()
    if title:
        ax.set_title(title)
    fig.subplots_adjust(0, 0, 1, 1)
    return fig


def _color(color):
    rgb = checks.finite_array(color, "color")
    if rgb.shape not in ((3,), (4,)) or rgb.min() < 0 or rgb.max() > 1:
        raise SurfmodError(f"color: expected 3 numbers in [0, 1], got {color!r}")
    return rgb


def render(
    objects,
    path,
    *,
    isocurves: bool = True,
    control_net: bool = False,
    iso_count: tuple[int, int] = (9, 9),
    elev: float = 28.0,
    azim: float = -58.0,
    size: tuple[float, float] = (6.0, 5.0),
    dpi: int = 100,
    color=(0.55, 0.68, 0.85),
    title: str | None = None,
) -> Path:
    """Write a shaded PNG of surfaces, curves, meshes, faces, tool paths and/or build123d
    shapes, headless.

    Surfaces are tessellated to 0.4 % of their size and drawn with ``iso_count``
    constant-u/constant-v iso-curves (``isocurves=True``) and their control net
    (``control_net=True``); shapes and faces read back (:class:`~surfmod.TrimmedFace`)
    are drawn inside their trim with their edges; curves and tool paths as lines.
    ``size`` is in inches at ``dpi``.  The write is atomic.

    >>> import surfmod as sm, numpy as np, tempfile, os
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> p = sm.render(sm.BezierSurface(net), os.path.join(tempfile.mkdtemp(), "b.png"))
    >>> open(p, "rb").read(8) == PNG_SIGNATURE
    True
    """
    target = target_path(path, "path", (".png",))
    items = _items(objects)
    try:
        iso_count = (checks.count(iso_count[0], "iso_count[0]", 0), checks.count(iso_count[1], "iso_count[1]", 0))
    except (TypeError, IndexError):
        raise SurfmodError(f"iso_count: expected two integers, got {iso_count!r}") from None
    dpi = checks.count(dpi, "dpi", minimum=10)
    fig = _figure(
        items, isocurves=isocurves, control_net=control_net, iso_count=iso_count, elev=elev, azim=azim,
        figsize=size, dpi=dpi, rgb=_color(color), title=title, detail=_Detail(),
    )
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return target


def repr_png(obj) -> bytes | None:
    """:func:`png_bytes` for a ``_repr_png_`` method: ``None`` when ``obj`` cannot be drawn,
    so that IPython shows the text repr instead of a traceback.

    >>> repr_png(Drawing()) is None   # nothing to draw
    True
    """
    try:
        return png_bytes(obj)
    except SurfmodError:
        return None


def polyline_runs(points: np.ndarray, kind: np.ndarray) -> dict:
    """The polyline ``points`` ``(N, 3)`` cut into runs of segments of one kind:
    ``{kind: [polyline, ...]}``, where ``kind`` ``(N - 1,)`` labels each segment (e.g. cut,
    link, rapid) -- how tool paths give their moves to a :class:`Drawing`.

    >>> p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [2, 1, 0.]])
    >>> {k: [len(r) for r in v] for k, v in polyline_runs(p, np.array([0, 1, 0])).items()}
    {0: [2, 2], 1: [2]}
    """
    points, kind = np.asarray(points, float), np.asarray(kind)
    if len(points) < 2:
        return {}
    cuts = np.flatnonzero(kind[1:] != kind[:-1]) + 1
    out: dict = {}
    for start, stop in zip(np.r_[0, cuts], np.r_[cuts, len(kind)]):
        out.setdefault(kind[start].item(), []).append(points[start : stop + 1])
    return out


def png_bytes(obj, size: tuple[int, int] = PNG_SIZE) -> bytes:
    """A small shaded PNG of ``obj`` (or a list of objects) in memory: what the
    ``_repr_png_`` of surfaces, curves, faces read back, meshes and tool paths returns, so
    that Jupyter shows them as pictures.  ``size`` is ``(width, height)`` in pixels; the
    tessellation is coarser than :func:`render`'s (0.8 % of the size, at most 5000
    triangles per object), and no file is written.

    >>> import surfmod as sm
    >>> png = png_bytes(sm.torus(3.0, 1.0), size=(200, 150))
    >>> png.startswith(PNG_SIGNATURE), int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    (True, 200, 150)
    """
    try:
        width, height = size
    except (TypeError, ValueError):
        raise SurfmodError(f"size: expected (width, height) in pixels, got {size!r:.60}") from None
    width = checks.count(width, "size[0]", MIN_PIXELS, MAX_PIXELS)
    height = checks.count(height, "size[1]", MIN_PIXELS, MAX_PIXELS)
    dpi = 100
    fig = _figure(
        _items(obj), isocurves=True, control_net=False, iso_count=(7, 7), elev=28.0, azim=-58.0,
        figsize=(width / dpi, height / dpi), dpi=dpi, rgb=_color((0.55, 0.68, 0.85)), title=None,
        detail=_Detail(PNG_TOLERANCE, PNG_TRIANGLES, PNG_TRIANGLES),
    )
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()
