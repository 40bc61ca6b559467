"""Headless shaded pictures (PNG) of surfaces, meshes and build123d shapes.

Matplotlib's Agg backend draws a ``Poly3DCollection`` of the tessellation, shaded with a
directional light (Lambert, two-sided, plus ambient), with the surface's iso-curves
(the lecture's "mesh of curves") and optionally its control net on top.  No display
server is needed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import checks
from ..atomic import atomic_path, target_path
from ..errors import SurfmodError
from ..surface import Surface
from .grid import mesh as grid_mesh
from .isocurves import isocurves as iso
from .polymesh import Mesh
from .tessellate import _surface_size, tessellate_surface

#: Display tessellation: chordal tolerance as a fraction of the object's size.
DISPLAY_TOLERANCE = 0.004
#: Above this many triangles a display mesh falls back to a grid (keeps a PNG < 2 s).
DISPLAY_TRIANGLES = 12000
LIGHT = np.array([0.4, -0.5, 0.77])


def _surface_mesh(s) -> Mesh:
    size = _surface_size(s)
    try:
        m = tessellate_surface(s, max(DISPLAY_TOLERANCE * size, 1e-12), DISPLAY_TRIANGLES)
        if len(m.faces) <= DISPLAY_TRIANGLES:
            return m
    except SurfmodError:
        pass
    return grid_mesh(s, 64, 64)


def _shape_mesh(shape) -> Mesh:
    from ..occ.mesh import brepmesh, shape_figures

    _figures, diag = shape_figures(shape, samples=2)
    fms = brepmesh(shape, max(DISPLAY_TOLERANCE * diag, 1e-9), 0.5)
    verts, tris, offset = [], [], 0
    for fm in fms:
        verts.append(fm.nodes)
        tris.append(fm.triangles + offset)
        offset += len(fm.nodes)
    return Mesh(np.concatenate(verts), np.concatenate(tris))


def _shape_edges(shape, samples: int = 48) -> list[np.ndarray]:
    from ..occ.mesh import curve_points
    from ..occ.topo import curve_of_edge

    out = []
    for e in shape.edges():
        try:
            curve, t0, t1 = curve_of_edge(e)
        except SurfmodError:
            continue
        out.append(curve_points(curve, np.linspace(t0, t1, samples)))
    return out


def _scene(obj, isocurves: bool, control_net: bool, iso_count, eye):
    """``(mesh, lines, net_points)`` for one object."""
    lines: list[np.ndarray] = []
    net = None
    if isinstance(obj, Mesh):
        return obj.triangulated(), lines, net
    if isinstance(obj, Surface):
        m = _surface_mesh(obj)
        if isocurves:
            lines.extend(_iso_lines(obj, m, iso_count, eye))
        if control_net and getattr(obj, "control_points", None) is not None:
            net = np.asarray(obj.control_points)
        return m, lines, net
    shape = getattr(obj, "wrapped", None)
    if shape is None or not hasattr(obj, "edges"):
        raise SurfmodError(f"objects: cannot render {type(obj).__name__} (expected a surface, Mesh or build123d shape)")
    m = _shape_mesh(obj)
    if isocurves:
        lines.extend(_shape_edges(obj))
    return m, lines, net


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
    """Write a shaded PNG of surfaces, meshes and/or build123d shapes, headless.

    Surfaces are tessellated to 0.4 % of their size and drawn with ``iso_count``
    constant-u/constant-v iso-curves (``isocurves=True``) and their control net
    (``control_net=True``); shapes are drawn with their edges.  The write is atomic.

    >>> import surfmod as sm, numpy as np, tempfile, os
    >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.mgrid[0:3, 0:3]
    >>> p = sm.render(sm.BezierSurface(net), os.path.join(tempfile.mkdtemp(), "b.png"))
    >>> open(p, "rb").read(4) == b"\\x89PNG"
    True
    """
    # A local Agg canvas: the caller's pyplot backend is left alone.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    target = target_path(path, "path", (".png",))
    items = list(objects) if isinstance(objects, (list, tuple)) else [objects]
    if not items:
        raise SurfmodError("objects: nothing to render")
    try:
        iso_count = (checks.count(iso_count[0], "iso_count[0]", 0), checks.count(iso_count[1], "iso_count[1]", 0))
    except (TypeError, IndexError):
        raise SurfmodError(f"iso_count: expected two integers, got {iso_count!r}") from None
    dpi = checks.count(dpi, "dpi", minimum=10)
    rgb = checks.finite_array(color, "color")
    if rgb.shape not in ((3,), (4,)) or rgb.min() < 0 or rgb.max() > 1:
        raise SurfmodError(f"color: expected 3 numbers in [0, 1], got {color!r}")

    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # curves and nets are drawn over the shading
    e, a = np.radians(elev), np.radians(azim)
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for obj in items:
        m, lines, net = _scene(obj, isocurves, control_net, iso_count, eye)
        tri = m.vertices[m.triangles()]
        lo, hi = np.minimum(lo, m.vertices.min(axis=0)), np.maximum(hi, m.vertices.max(axis=0))
        fc = shade(tri, rgb)  # edges in the face colour hide anti-aliasing seams
        ax.add_collection3d(Poly3DCollection(tri, facecolors=fc, edgecolors=fc, linewidths=0.3, zorder=1))
        if lines:
            ax.add_collection3d(Line3DCollection(lines, colors=(0.1, 0.1, 0.15, 0.8), linewidths=0.6, zorder=2))
        if net is not None:
            segs = list(net) + list(net.transpose(1, 0, 2))
            ax.add_collection3d(Line3DCollection(segs, colors=(0.85, 0.2, 0.1, 0.9), linewidths=0.8, zorder=3))
            flat = net.reshape(-1, 3)
            ax.scatter(flat[:, 0], flat[:, 1], flat[:, 2], color=(0.85, 0.2, 0.1), s=6, depthshade=False, zorder=4)
            lo, hi = np.minimum(lo, flat.min(axis=0)), np.maximum(hi, flat.max(axis=0))
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
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return target
