"""The job in the browser (surfmod/cam/job_view.py): one HTML file, plotly.js inside.

The page's stock is the verifier's (kept with its verdict), held here against the tests'
own stock simulation (``tests/stock_sim.py``) run on the program; the page's content is
read without a browser (no script from the network, a trace per operation, the stock
where material is left, the moves within their bound); and the page is rendered by
headless Chromium (skipped where it is missing): the part's pixels are on the
screenshot, found by its colour, and no script failed.
"""

from __future__ import annotations

import colorsys
import json
import math
import re
from dataclasses import replace

import build123d as bd
import numpy as np
import pytest
from PIL import Image
from scipy import ndimage
from scipy.spatial import cKDTree

import chromium
import surfmod as sm
from surfmod.cam import job_view
from surfmod.cam.drop_cutter import part_triangles
from surfmod.cam.post import programs
from surfmod.cam.roughing import RAPID
from surfmod.cli import main
from stock_sim import Cutter, Stock, parse_gcode, part_height, simulate

ROUGH, FINISH = ("flat", 2.0), ("ball", 1.0)


def boss_part():
    return bd.Box(12, 12, 4) + bd.Pos(0, 0, 3) * bd.Cylinder(3, 2)


@pytest.fixture(scope="module")
def job():
    return sm.machine(boss_part(), 1.0, [sm.Rough(sm.Tool(*ROUGH), stepdown=2.0, allowance=0.3),
                                         sm.Finish(sm.Tool(*FINISH), scallop=0.05)])


def _array(spec) -> np.ndarray:
    """A typed array of the page back as numbers."""
    import base64

    a = np.frombuffer(base64.b64decode(spec["bdata"]), dtype="<" + spec["dtype"])
    return a.reshape([int(n) for n in spec["shape"].split(",")]) if "shape" in spec else a


def _figure(page: str) -> list:
    """The traces the page hands to ``Plotly.newPlot``."""
    start = page.index("Plotly.newPlot(")
    data = page[page.index("[", start):]
    return json.JSONDecoder().raw_decode(data)[0]


def test_the_stock_kept_is_the_independent_simulation(job):
    """The verifier's stock (what the page draws) against stock_sim on the same grid: the
    heights within the sweep's sampling (its stamps lie above the exact sweep), the material
    on the part, normal to it, within 0.002 mm on the slopes below 60 deg."""
    field = job.verification.stock
    stock = Stock(job.stock, field.cell)
    assert stock.top.shape == field.top.shape
    tri, _ = part_triangles(job.part, 0.001)
    part = part_height(tri, stock.x, stock.y)
    simulate(parse_gcode(programs(job)[0]), {1: Cutter(*ROUGH), 2: Cutter(*FINISH)}, stock, part)
    above = field.top - stock.top
    assert above.min() > -1e-9 and above.max() < 0.005, (above.min(), above.max())
    gx, gy = np.gradient(np.where(np.isfinite(part), part, np.nan), field.cell)
    cos = 1 / np.sqrt(1 + gx * gx + gy * gy)
    judged = ndimage.binary_erosion(np.isfinite(part), iterations=2) & (cos > math.cos(math.radians(60)))
    judged &= np.isfinite(field.left)
    assert judged.sum() > 0.5 * judged.size
    err = np.abs((stock.top - part) * cos - field.left)[judged]
    assert err.max() < 0.002, err.max()
    # the fillet the ball leaves round the boss's foot is material the page must show
    assert np.nanmax(field.left) > 0.3


def test_the_verifier_keeps_a_bounded_stock_losing_no_material_left(job, monkeypatch):
    from surfmod.cam import verify

    full = job.verification.stock
    monkeypatch.setattr(verify, "KEPT_NODES", 500)
    kept = verify.verify_job(job).stock
    assert kept.top.size <= 500 < full.top.size and not kept.top.flags.writeable
    assert np.nanmax(kept.left) == np.nanmax(full.left) and kept.top.max() == full.top.max()
    f = round(kept.cell / full.cell)
    assert f >= 2 and kept.origin[0] == pytest.approx(full.origin[0] + 0.5 * (f - 1) * full.cell)


def test_page_is_self_contained_with_a_trace_per_operation(job):
    page = job_view.job_html(job)
    assert page.startswith("<html>") or page.lstrip().lower().startswith("<!doctype html>")
    assert not re.search(r"<script[^>]*\bsrc=", page), "a script from outside the page"
    assert "window.Plotly = Plotly" in page  # plotly.js itself is inside
    traces = _figure(page)
    kinds = [t["type"] for t in traces]
    assert kinds[0] == "mesh3d" and kinds[-1] == "surface"
    lines = [t["name"] for t in traces if t["type"] == "scatter3d"]
    assert lines == ["1 roughing (T1 flat end mill r=2)", "1 roughing: rapids",
                     "2 finishing (T2 ball end mill r=1)", "2 finishing: rapids"]
    assert "verified: every promise holds" in page
    assert f"time estimate {int(job.time_estimate // 60)} min" in page
    # the stock is drawn exactly where more than the residual limit is left on the part,
    # at the verifier's heights, coloured by how much
    field = job.verification.stock.coarsened(job_view.VIEW_NODES)
    limit = next(f.limit for f in job.verification.findings if f.what.startswith("residual"))
    stock = traces[-1]
    z, colour = _array(stock["z"]).T, _array(stock["surfacecolor"]).T
    shown = np.nan_to_num(field.left, nan=-1.0) > limit
    assert shown.sum() > 20 and np.array_equal(np.isfinite(z), shown)
    assert np.allclose(z[shown], field.top[shown], atol=1e-5)
    assert np.allclose(colour[shown], field.left[shown], atol=1e-5)
    assert len(page) < 4.82e6 + 0.6e6  # plotly.js and this small job's data


def test_moves_kept_within_the_bound_are_the_jobs(job, monkeypatch):
    """With room for 400 locations the page draws at most that many, each a location of
    the job, and a chord as a cut (a rapid) only where every move it stands for cuts (is
    a rapid)."""
    monkeypatch.setattr(job_view, "VIEW_POINTS", 400)
    traces = [t for t in job_view.job_figure(job)["data"] if t["type"] == "scatter3d"]
    total = sum(len(op.motion.points) for op in job.operations)
    for k, op in enumerate(job.operations):
        drawn = np.concatenate([np.column_stack([_array(t[a]) for a in "xyz"]) for t in traces
                                if t["legendgroup"] == f"op{k + 1}"])
        drawn = np.unique(drawn[~np.isnan(drawn).any(axis=1)], axis=0)
        gap, _ = cKDTree(op.motion.points).query(drawn)
        assert gap.max() < 1e-4  # float32 on the page
        assert 100 < len(drawn) <= 400 * len(op.motion.points) // total
        cutting = np.asarray(op.motion.kind) != RAPID
        index, label = job_view.kept_locations(cutting, 50)
        assert len(index) <= 50 and index[0] == 0 and index[-1] == len(cutting) - 1
        for (a, b), lab in zip(zip(index[:-1], index[1:]), label):
            share = cutting[a + 1:b + 1]
            assert lab == (1 if share.all() else 0 if not share.any() else -1)
        assert (label == -1).any() and (label == 1).any()


def test_part_and_stock_kept_within_their_bounds(job, monkeypatch):
    """The part within its triangles (BRepMesh coarser where its estimate passes the
    mesh's bound) and the stock within its nodes, the most left kept."""
    monkeypatch.setattr(job_view, "VIEW_TRIANGLES", 60)
    monkeypatch.setattr(job_view, "MESH_TRIANGLES", 100)
    monkeypatch.setattr(job_view, "VIEW_NODES", 100)
    data = job_view.job_figure(job)["data"]
    part, stock = data[0], data[-1]
    assert 12 <= len(_array(part["i"])) <= 60 and part["name"].startswith(f"part ({len(_array(part['i']))} ")
    z = _array(stock["z"])
    assert z.size <= 100 and len(_array(stock["x"])) * len(_array(stock["y"])) == z.size
    assert np.nanmax(_array(stock["surfacecolor"])) == pytest.approx(np.nanmax(job.verification.stock.left), 1e-6)


def test_a_job_not_verified_says_so(job):
    page = job_view.job_html(replace(job, verification=None))
    assert "not verified (no stock model)" in page
    assert [t["type"] for t in _figure(page)].count("surface") == 0


def test_repr_html_is_the_page_in_a_div(job):
    div = job._repr_html_()
    assert "<html" not in div.lower() and 'id="surfmod-job"' in div and "window.Plotly = Plotly" in div
    assert _figure(div) == _figure(job_view.job_html(job))


def test_cli_writes_the_page_and_refuses_a_wrong_suffix(tmp_path, capsys):
    part = tmp_path / "boss.step"
    bd.export_step(boss_part(), str(part))
    args = ["machine", str(part), "--stock-margin", "1", "--rough", "flat:2", "--finish", "ball:1",
            "--scallop", "0.05", "--stepdown", "2", "--allowance", "0.3", "--no-progress"]
    page = tmp_path / "job.html"
    assert main(args + ["--out", str(tmp_path / "a.ngc"), "--html", str(page)]) == 0
    assert f"wrote {page}" in capsys.readouterr().out
    assert len(_figure(page.read_text())) == 6
    assert main(args + ["--out", str(tmp_path / "b.ngc"), "--html", str(tmp_path / "job.txt")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error: html: expected a file ending in .html" in err[0]
    assert not (tmp_path / "b.ngc").exists() and not (tmp_path / "job.txt").exists()


def part_pixels(png) -> int:
    """Pixels of the part's hue (lit or in shade), which no line or stock colour has."""
    r, g, b = (int(job_view.PART_COLOR[k:k + 2], 16) / 255 for k in (1, 3, 5))
    hue = colorsys.rgb_to_hsv(r, g, b)[0] * 360
    hsv = np.asarray(Image.open(png).convert("HSV"), float)
    h, s, v = hsv[..., 0] * 360 / 255, hsv[..., 1] / 255, hsv[..., 2] / 255
    return int(((np.abs(h - hue) < 12) & (s > 0.25) & (v > 0.15)).sum())


@pytest.mark.skipif(chromium.find() is None, reason="chromium not installed (Debian: apt-get install chromium)")
def test_page_renders_in_headless_chromium(job, tmp_path):
    """The page draws the part (at least 1 % of a 900 x 700 screenshot in its colour) and
    no script fails; the same page with the part switched off has none of its pixels."""
    import plotly.io as pio

    page = tmp_path / "job.html"
    job_view.write_html(job, page)
    errors = chromium.screenshot(page, tmp_path / "job.png")
    assert errors == []
    assert part_pixels(tmp_path / "job.png") > 0.01 * 900 * 700
    figure = job_view.job_figure(job)
    figure["data"][0]["visible"] = False
    (tmp_path / "off.html").write_text(pio.to_html(figure, include_plotlyjs=True, validate=False))
    assert chromium.screenshot(tmp_path / "off.html", tmp_path / "off.png") == []
    assert part_pixels(tmp_path / "off.png") < 0.001 * 900 * 700


@pytest.mark.skipif(chromium.find() is None, reason="chromium not installed (Debian: apt-get install chromium)")
def test_chromium_reports_a_failing_script_and_a_page_needing_the_network(tmp_path):
    """The console scan above can fail: a script error is reported, and so is a page that
    loads plotly.js from the network (no host name resolves there)."""
    page = tmp_path / "cdn.html"
    page.write_text('<html><head><script src="https://cdn.plot.ly/plotly-2.35.2.min.js"></script></head>'
                    '<body><div id="d"></div><script>Plotly.newPlot("d", [{y: [1, 2]}]);</script></body></html>')
    errors = chromium.screenshot(page, tmp_path / "cdn.png", (300, 200), budget_ms=2000)
    assert len(errors) == 1 and "Plotly is not defined" in errors[0]
