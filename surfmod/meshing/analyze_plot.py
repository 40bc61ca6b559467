"""PNG pictures of :func:`surfmod.meshing.analyze.analyze` results, headless.

An orthographic view drawn by the painter's algorithm (triangles sorted far to near) on a
local ``matplotlib.figure.Figure`` with a ``FigureCanvasAgg``: no pyplot, no global
backend switch, no display.  Curvature maps get a colour scale bar; combs are drawn
over a light grey shading.
"""

from __future__ import annotations

import numpy as np

from ..atomic import atomic_path, target_path


LABELS = {
    "gaussian": "Gaussian curvature K",
    "mean": "mean curvature H",
    "max_abs": "max |k1|, |k2|",
    "isophote": "n . L",
}


def _view_basis(eye):
    w = eye / np.linalg.norm(eye)
    up = np.array([0.0, 0.0, 1.0]) if abs(w[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    x = np.cross(up, w)
    x /= np.linalg.norm(x)
    return x, np.cross(w, x), w


def _shade(normals_tri, eye):
    lam = np.abs(normals_tri @ (eye / np.linalg.norm(eye)))
    return 0.45 + 0.55 * lam


def write_analysis_png(result, out, eye, *, title=None, stripes: int = 8, dpi: int = 110):
    """Draw ``result`` into the PNG ``out`` (atomic write); returns the path."""
    import matplotlib  # heavy: imported on the first picture only
    import matplotlib.cm as cm
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import Normalize, TwoSlopeNorm
    from matplotlib.figure import Figure

    target = target_path(out, "out", (".png",))
    bx, by, bz = _view_basis(np.asarray(eye, float))
    polys, depth, colours, scalar, kept = [], [], [], [], []
    kind = result.kind
    for p in result.patches:
        n = p.normals[p.triangles].mean(axis=1)
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
        keep = (n @ bz > -1e-3) if p.outside_only else np.ones(len(n), bool)  # back faces of solids
        kept.append(p.triangles[keep])
        n, tri = n[keep], p.points[kept[-1]]
        polys.append(np.stack([tri @ bx, tri @ by], axis=-1))
        depth.append((tri @ bz).mean(axis=1))
        colours.append(_shade(n, eye))
        if kind == "zebra":
            angle = np.arccos(np.clip(n @ result.light, -1.0, 1.0))
            scalar.append((np.minimum(np.floor(angle * (2 * stripes) / np.pi), 2 * stripes - 1) % 2).astype(float))
        else:
            scalar.append(p.values[kept[-1]].mean(axis=1))
    polys, depth = np.concatenate(polys), np.concatenate(depth)
    shade, values = np.concatenate(colours), np.concatenate(scalar)
    order = np.argsort(depth)  # far first: larger depth along the eye vector is nearer
    fig = Figure(figsize=(7.0, 5.6), dpi=dpi)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.02, 0.04, 0.8 if kind in LABELS else 0.96, 0.88))
    mappable = None
    if kind == "zebra":
        rgb = np.repeat((0.08 + 0.9 * values)[:, None], 3, axis=1) * (0.75 + 0.25 * shade)[:, None]
    elif kind == "comb":
        rgb = np.repeat((0.82 * shade)[:, None], 3, axis=1)
    else:
        finite = values[np.isfinite(values)]
        lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        if hi - lo < 1e-12 * max(1.0, abs(hi)):
            lo, hi = lo - 0.5 * max(abs(lo), 1e-9), hi + 0.5 * max(abs(hi), 1e-9)
        norm = TwoSlopeNorm(0.0, lo, hi) if kind in ("gaussian", "mean") and lo < 0 < hi else Normalize(lo, hi)
        cmap = matplotlib.colormaps["coolwarm" if kind in ("gaussian", "mean") else "viridis"]
        rgb = cmap(norm(values))[:, :3] * (0.7 + 0.3 * shade)[:, None]
        if kind == "isophote":  # dark lines where a triangle straddles an isophote level
            levels = np.linspace(-1, 1, 2 * stripes + 1)
            lv = np.concatenate([np.digitize(p.values[t], levels) for p, t in zip(result.patches, kept)])
            rgb[lv.min(axis=1) != lv.max(axis=1)] *= 0.15
        mappable = cm.ScalarMappable(norm=norm, cmap=cmap)
    ax.add_collection(PolyCollection(polys[order], facecolors=np.clip(rgb[order], 0, 1),
                                     edgecolors=np.clip(rgb[order], 0, 1), linewidths=0.6))
    allpts = polys.reshape(-1, 2)
    lo2, hi2 = allpts.min(axis=0), allpts.max(axis=0)
    for comb in result.combs:
        base = np.stack([comb.points @ bx, comb.points @ by], 1)
        tips = np.stack([comb.tips @ bx, comb.tips @ by], 1)
        ax.add_collection(LineCollection(np.stack([base, tips], 1), colors=(0.85, 0.25, 0.1, 0.7), linewidths=0.5))
        ax.plot(tips[:, 0], tips[:, 1], color=(0.6, 0.1, 0.05), linewidth=0.8)
        ax.plot(base[:, 0], base[:, 1], color=(0.1, 0.1, 0.2), linewidth=0.8)
        lo2, hi2 = np.minimum(lo2, tips.min(axis=0)), np.maximum(hi2, tips.max(axis=0))
    pad = 0.03 * float(np.max(hi2 - lo2) or 1.0)
    ax.set_xlim(lo2[0] - pad, hi2[0] + pad)
    ax.set_ylim(lo2[1] - pad, hi2[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if mappable is not None:
        cax = fig.add_axes((0.86, 0.12, 0.03, 0.72))
        fig.colorbar(mappable, cax=cax, label=LABELS[kind])
    fair = result.patches[0].fairness if len(result.patches) == 1 else None
    head = title or f"{kind}" + (f"  (bending {fair.bending:.4g}, variation {fair.variation:.4g})" if fair else "")
    fig.suptitle(head, fontsize=10)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return target
