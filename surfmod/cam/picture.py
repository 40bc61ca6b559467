"""A picture of a job: its moves over the shaded part (rapids thin and grey)."""

from __future__ import annotations

import io

import numpy as np

from ..atomic import atomic_path, target_path
from ..meshing.render import shade
from .roughing import RAPID

COLOURS = [(0.85, 0.35, 0.1), (0.1, 0.45, 0.85), (0.2, 0.65, 0.25), (0.6, 0.2, 0.7)]


def _figure(job, size=(7.0, 5.5), dpi=110):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from .drop_cutter import part_triangles

    lo, hi = job.stock
    tri, _ = part_triangles(job.part, 0.002 * float(np.ptp(job.stock, axis=0).max()))
    fig = Figure(figsize=size, dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False
    fc = shade(tri, np.array([0.7, 0.72, 0.78]))
    ax.add_collection3d(Poly3DCollection(tri, facecolors=fc, edgecolors=fc, linewidths=0.2, zorder=1))
    for k, op in enumerate(job.operations):
        p, kind = op.motion.points, op.motion.kind
        seg = np.stack([p[:-1], p[1:]], axis=1)
        cut = kind[1:] != RAPID
        ax.add_collection3d(Line3DCollection(seg[cut], colors=[COLOURS[k % len(COLOURS)]], linewidths=0.4,
                                             zorder=2, label=f"{op.name} ({op.tool})"))
        ax.add_collection3d(Line3DCollection(seg[~cut], colors=[(0.5, 0.5, 0.5, 0.5)], linewidths=0.2, zorder=2))
    hi = np.array([hi[0], hi[1], job.safe_height])
    centre, extent = (lo + hi) / 2, np.maximum(hi - lo, float(np.max(hi - lo)) / 3)
    for axis, c, e in zip("xyz", centre, extent):
        getattr(ax, f"set_{axis}lim")(c - e / 2, c + e / 2)
    ax.set_box_aspect(tuple(extent))
    ax.view_init(elev=32, azim=-60)
    ax.set_axis_off()
    ax.legend(loc="upper left", fontsize=7)
    fig.subplots_adjust(0, 0, 1, 1)
    return fig


def job_png(job) -> bytes:
    """PNG bytes of the job's picture."""
    buf = io.BytesIO()
    _figure(job).savefig(buf, format="png")
    return buf.getvalue()


def write_png(job, path):
    """Write the picture atomically; returns the path."""
    target = target_path(path, "png", (".png",))
    data = job_png(job)
    with atomic_path(target) as tmp:
        tmp.write_bytes(data)
    return target
