"""A job in the browser: one self-contained HTML file (plotly's offline HTML), which
``surfmod machine --html`` writes and a notebook shows (``Job._repr_html_``).

Its traces are the part, each operation's cuts and rapids, and the stock the verifier swept
(``job.verification.stock``) where more than the residual limit is left; the page is bounded
before it is written (``VIEW_TRIANGLES``, ``VIEW_POINTS``, ``VIEW_NODES``).
See :doc:`/guide/cam` (section "Job view").
"""

from __future__ import annotations

import base64
import html
import math

import numpy as np

from ..atomic import atomic_path, target_path
from ..meshing.brep import triangle_estimate
from ..meshing.polymesh import Mesh
from ..meshing.render import display_mesh, polyline_runs
from .roughing import RAPID

#: the part's colour: a blue that no operation and no stock colour uses (the rendering test
#: finds the part on a screenshot by its hue)
PART_COLOR = "#5b86c9"
#: one colour per operation, in order (no blue), the rapids' and the stock's scale
OPERATION_COLORS = ("#e4731b", "#2ca02c", "#b03fb5", "#d62728", "#8c6d1f", "#17a589")
RAPID_COLOR = "#9a9a9a"
STOCK_SCALE = "YlOrRd"
#: the bounds of what a page holds (see the module)
VIEW_TRIANGLES = 20_000
VIEW_POINTS = 50_000
VIEW_NODES = 40_000
#: triangles BRepMesh may make for the part (by the curvature estimate, before it runs)
MESH_TRIANGLES = 200_000
#: BRepMesh's deflection for the part, as a share of the stock's largest side
VIEW_DEFLECTION = 0.0005
#: the least material the stock surface shows (mm), where no finishing sets a limit
LEAST_LEFT = 1e-3


def _typed(a, dtype: str = "f4") -> dict:
    """An array as plotly.js's typed-array spec (base64 of its little-endian bytes)."""
    a = np.ascontiguousarray(a, dtype="<" + dtype)
    out = {"dtype": dtype, "bdata": base64.b64encode(a.tobytes()).decode("ascii")}
    if a.ndim == 2:
        out["shape"] = f"{a.shape[0]},{a.shape[1]}"
    return out


def _part_trace(job) -> dict:
    from .drop_cutter import part_triangles

    deflection = VIEW_DEFLECTION * float(np.ptp(job.stock, axis=0).max())
    estimate, _ = triangle_estimate(job.part, deflection)
    if estimate > MESH_TRIANGLES:  # a triangle's sag grows with its area: the count falls as 1 / deflection
        deflection *= 1.1 * estimate / MESH_TRIANGLES
    tri, _ = part_triangles(job.part, deflection)
    # BRepMesh repeats a node for each face it bounds: merge them, then simplify to the bound
    nodes, index = np.unique(tri.reshape(-1, 3), axis=0, return_inverse=True)
    mesh = display_mesh(Mesh(nodes, index.reshape(-1, 3)), VIEW_TRIANGLES)
    faces = np.asarray(mesh.faces)
    return {"type": "mesh3d", "name": f"part ({len(faces):,} triangles)", "showlegend": True,
            "x": _typed(mesh.vertices[:, 0]), "y": _typed(mesh.vertices[:, 1]), "z": _typed(mesh.vertices[:, 2]),
            "i": _typed(faces[:, 0], "i4"), "j": _typed(faces[:, 1], "i4"), "k": _typed(faces[:, 2], "i4"),
            "color": PART_COLOR, "flatshading": True, "hoverinfo": "skip",
            "lighting": {"ambient": 0.7, "diffuse": 0.5, "specular": 0.05, "roughness": 0.9},
            "lightposition": {"x": 1e5, "y": -2e5, "z": 3e5}}


def kept_locations(cutting: np.ndarray, budget: int):
    """Of ``n`` tool locations (``cutting[i]``: the move to location ``i`` cuts), every
    ``s``-th and the last, at most ``budget``; and per chord between two kept ones 1 where
    all its moves cut, 0 where all are rapids, -1 where they mix."""
    n = len(cutting)
    s = max(1, math.ceil(n / max(budget - 1, 1)))
    index = np.unique(np.r_[np.arange(0, n, s), n - 1])
    cuts = np.r_[0, np.cumsum(cutting[1:])]  # cutting moves up to each location
    done, span = np.diff(cuts[index]), np.diff(index)
    label = np.where(done == span, 1, np.where(done == 0, 0, -1))
    return index, label


def _polylines(runs: list) -> np.ndarray:
    """Polylines joined into one array, NaN rows between them (plotly's gaps)."""
    gap = np.full((1, 3), np.nan)
    return np.concatenate([piece for run in runs for piece in (run, gap)][:-1])


def _line_trace(points: np.ndarray, name: str, line: dict, group: str, shown: bool) -> dict:
    return {"type": "scatter3d", "mode": "lines", "name": name, "legendgroup": group, "line": line,
            "visible": True if shown else "legendonly",
            "x": _typed(points[:, 0]), "y": _typed(points[:, 1]), "z": _typed(points[:, 2]), "hoverinfo": "name"}


def _move_traces(job) -> list[dict]:
    counts = [len(op.motion.points) for op in job.operations]
    total = max(sum(counts), 1)
    traces = []
    for k, (op, n) in enumerate(zip(job.operations, counts)):
        if n < 2:
            continue
        budget = max(2, VIEW_POINTS * n // total)
        index, label = kept_locations(np.asarray(op.motion.kind) != RAPID, budget)
        runs = polyline_runs(np.asarray(op.motion.points, float)[index], label)
        group = f"op{k + 1}"
        if runs.get(1):
            colour = OPERATION_COLORS[k % len(OPERATION_COLORS)]
            traces.append(_line_trace(_polylines(runs[1]), f"{k + 1} {op.name} ({op.tool})",
                                      {"color": colour, "width": 2}, group, k == len(counts) - 1))
        if runs.get(0):
            traces.append(_line_trace(_polylines(runs[0]), f"{k + 1} {op.name}: rapids",
                                      {"color": RAPID_COLOR, "width": 1.5, "dash": "dash"}, group, False))
    return traces


def _residual_limit(job) -> float:
    found = [f for f in job.verification.findings if f.what.startswith("residual")]
    return max(float(found[-1].limit), LEAST_LEFT) if found else LEAST_LEFT


def _stock_trace(job) -> dict | None:
    """The stock where more than the residual limit is left on the part (None: no model)."""
    field = getattr(job.verification, "stock", None)
    if field is None:
        return None
    field = field.coarsened(VIEW_NODES)
    shown = _residual_limit(job)
    left = np.where(np.nan_to_num(field.left, nan=-1.0) > shown, field.left, np.nan)
    most = float(np.nanmax(left)) if np.isfinite(left).any() else 0.0
    name = (f"stock left > {shown:.3g} mm (up to {most:.3g})" if most > 0
            else f"stock: nowhere more than {shown:.3g} mm left")
    # plotly's surface takes z[row = y][column = x]
    return {"type": "surface", "name": name, "showlegend": True, "showscale": True,
            "x": _typed(field.x), "y": _typed(field.y), "z": _typed(np.where(np.isfinite(left), field.top, np.nan).T),
            "surfacecolor": _typed(left.T), "colorscale": STOCK_SCALE, "reversescale": True, "cmin": 0.0, "cmax": max(most, shown),
            "colorbar": {"title": {"text": "left (mm)"}, "len": 0.6, "thickness": 14},
            "hovertemplate": "left %{surfacecolor:.3f} mm<extra></extra>"}


def _verdict(job) -> str:
    v = job.verification
    if v is None:
        return "not verified (no stock model)"
    if v.ok:
        return "verified: every promise holds"
    return "VERIFICATION FAILED: " + ", ".join(f.what for f in v.findings if not f.ok)


def title(job) -> str:
    """The page's title: the stock, the operations and their tools, the time, the verdict."""
    lo, hi = np.asarray(job.stock, float)
    m, s = divmod(job.time_estimate, 60)
    ops = ", ".join(f"{k + 1} {op.name} {op.tool}" for k, op in enumerate(job.operations))
    return (f"job: stock {hi[0] - lo[0]:.4g} x {hi[1] - lo[1]:.4g} x {hi[2] - lo[2]:.4g} mm, {ops}; "
            f"time estimate {int(m)} min {s:04.1f} s; {_verdict(job)}")


def job_figure(job) -> dict:
    """The plotly figure of ``job`` as a plain dict (``data``, ``layout``)."""
    data = [_part_trace(job), *_move_traces(job)]
    stock = _stock_trace(job)
    if stock is not None:
        data.append(stock)
    axis = {"showbackground": False, "gridcolor": "#dddddd", "zerolinecolor": "#bbbbbb"}
    # the title wrapped at the operations and the verdict (plotly breaks lines at <br>)
    text = "<br>".join(html.escape(part) for part in title(job).split("; "))
    layout = {"title": {"text": text, "font": {"size": 13}, "x": 0.01, "xanchor": "left"},
              "paper_bgcolor": "white", "margin": {"l": 0, "r": 0, "t": 70, "b": 0},
              "legend": {"x": 0.0, "y": 0.92, "bgcolor": "rgba(255,255,255,0.7)"},
              "scene": {"aspectmode": "data", "xaxis": dict(axis, title={"text": "x (mm)"}),
                        "yaxis": dict(axis, title={"text": "y (mm)"}), "zaxis": dict(axis, title={"text": "z (mm)"}),
                        "camera": {"eye": {"x": 1.1, "y": -1.5, "z": 1.0}}}}
    return {"data": data, "layout": layout}


def job_html(job, *, full_html: bool = True) -> str:
    """The job's page (see the module): a whole HTML document, or with ``full_html=False``
    the ``<div>`` a notebook shows (plotly.js inside it as well)."""
    import plotly.io as pio

    page = pio.to_html(job_figure(job), config={"displaylogo": False, "responsive": True}, include_plotlyjs=True,
                       full_html=full_html, validate=False, div_id="surfmod-job",
                       default_height="100%" if full_html else "620px")
    # the page is the window's height: without the body's margin no scroll bar
    return page.replace("<style>html, body {height: 100%;}</style>",
                        "<style>html, body {height: 100%; margin: 0;}</style>", 1)


def write_html(job, path):
    """Write the job's page atomically; returns the path."""
    target = target_path(path, "html", (".html", ".htm"))
    text = job_html(job)
    with atomic_path(target) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return target
