"""Bull-nose drop-cutter and the Tool / tool table: against a brute-force sampling of the
tool surface, against OpenCAMLib's BullCutter, and on exact faces against closed forms."""

import json
import subprocess
import sys

import build123d as bd
import numpy as np
import pytest

import surfmod as sm
from surfmod.cam.cutters import Ball, Bull, Flat
from surfmod.cam.drop_cutter import TriangleGrid, drop
from surfmod.cam.tool import load_tool_table, parse_tool
from surfmod.cam.toolpath import drop_cutter


def brute_bull(tri, q, R, c, n=400):
    """Highest tip at ``q`` over a dense sampling of each triangle (a lower bound that
    converges to the exact height as the sampling grows)."""
    a = R - c
    s, t = np.meshgrid(np.linspace(0, 1, n), np.linspace(0, 1, n))
    keep = s + t <= 1
    s, t = s[keep], t[keep]
    best = -np.inf
    for T in tri:
        p = T[0] + s[:, None] * (T[1] - T[0]) + t[:, None] * (T[2] - T[0])
        d = np.hypot(p[:, 0] - q[0], p[:, 1] - q[1])
        inside = d <= R
        f = c - np.sqrt(np.maximum(c * c - np.maximum(d - a, 0) ** 2, 0))
        if inside.any():
            best = max(best, float((p[inside, 2] - f[inside]).max()))
    return best


def test_bull_drop_brute_force():
    rng = np.random.default_rng(7)
    tri = rng.uniform(-3, 3, (3, 3, 3))
    R, c = 1.5, 0.5
    xy = rng.uniform(-2.5, 2.5, (12, 2))
    z = drop(TriangleGrid(tri, R), Bull(R, c), xy)
    for q, zq in zip(xy, z):
        ref = brute_bull(tri, q, R, c)
        if np.isfinite(ref):
            # sampling step 6/400: the exact height is above every sample, within ~step·slope
            assert ref - 1e-12 <= zq <= ref + 0.05


def test_bull_limits_are_ball_and_flat():
    rng = np.random.default_rng(3)
    tri = rng.uniform(-4, 4, (20, 3, 3))
    xy = rng.uniform(-4, 4, (500, 2))
    grid = TriangleGrid(tri, 2.0)
    ball, flat = drop(grid, Ball(2.0), xy), drop(grid, Flat(2.0), xy)
    near_ball = drop(grid, Bull(2.0, 2.0 * (1 - 1e-9)), xy)
    near_flat = drop(grid, Bull(2.0, 1e-9), xy)
    assert np.nanmax(np.abs(near_ball - ball)) < 1e-6
    assert np.nanmax(np.abs(near_flat - flat)) < 1e-6


OCL_SCRIPT = """
import sys, numpy as np, opencamlib as ocl
data = np.load(sys.argv[1])
surf = ocl.STLSurf()
for t in data["tri"]:
    surf.addTriangle(ocl.Triangle(*[ocl.Point(*map(float, p)) for p in t]))
bdc = ocl.BatchDropCutter()
bdc.setSTL(surf)
R, c = map(float, data["tool"])
cutter = ocl.BullCutter(2 * R, c, 50)  # held: BatchDropCutter keeps only a pointer
bdc.setCutter(cutter)
for x, y in data["xy"]:
    bdc.appendPoint(ocl.CLPoint(float(x), float(y), -100))
bdc.run()
np.save(sys.argv[2], np.array([p.z for p in bdc.getCLPoints()]))
"""


def test_bull_equals_opencamlib(tmp_path):
    """OCL in its own interpreter, away from OCP's libraries."""
    pytest.importorskip("opencamlib")
    rng = np.random.default_rng(11)
    tri = rng.uniform(-5, 5, (40, 3, 3))
    tri[..., 2] *= 0.6
    R, c = 2.0, 0.7
    xy = rng.uniform(-6, 6, (2000, 2))
    np.savez(tmp_path / "in.npz", tri=tri, xy=xy, tool=[R, c])
    subprocess.run([sys.executable, "-c", OCL_SCRIPT, str(tmp_path / "in.npz"), str(tmp_path / "out.npy")],
                   check=True, timeout=300)
    ref = np.load(tmp_path / "out.npy")
    z = drop(TriangleGrid(tri, R), Bull(R, c), xy)
    z = np.where(np.isnan(z), -100, z)
    assert (ref > -100).sum() > 1500
    # OCL solves the torus-edge contact iteratively to ~1e-10
    assert np.abs(z - ref).max() < 1e-8


def test_bull_exact_on_sphere():
    """A bull nose on a sphere of radius 5: the tube centre rides the sphere of radius
    5 + c, on the ring a from the axis: tip = sqrt((5 + c)² - (|q| - a)²) - c.  On a
    coarse mesh (tolerance 0.05, its heights 0.0098 low): the polish must make up all of
    it (at the default radius / 1000 the sphere's 125,000 triangles took 6 CPU seconds)."""
    R, c = 1.0, 0.4
    a = R - c
    q = np.array([[1.5, 0.5], [2.0, -1.0], [0.3, 2.2]])
    z, contact = drop_cutter(bd.Sphere(5.0), sm.Tool("bull", R, c), q, exact=True, tolerance=0.05)
    rho = np.hypot(q[:, 0], q[:, 1])
    ref = np.sqrt((5 + c) ** 2 - (rho - a) ** 2) - c
    assert np.abs(z - ref).max() < 1e-11
    assert np.abs(np.linalg.norm(contact, axis=1) - 5.0).max() < 1e-11


def test_bull_plate_toolpath():
    plate = sm.plane((0, 0, 1), (10, 0, 1), (0, 10, 1))
    tool = sm.Tool("bull", 2.0, 0.5)
    tp = sm.toolpath(plate, tool, scallop=0.02)
    # stepover = 2a + 2 sqrt(2 c h - h²) on flat ground, and the tip rides on z = 1
    assert tp.stepover <= 3.0 + 2 * np.sqrt(2 * 0.5 * 0.02 - 0.02**2) + 1e-12
    assert np.abs(tp.points[:, 2] - 1).max() < 1e-12
    assert abs(tool.scallop_for_stepover(tool.stepover_for_scallop(0.02)) - 0.02) < 1e-12


@pytest.mark.parametrize("make, word", [
    (lambda: sm.Tool("bull", 2.0, 2.0), "corner_radius"),
    (lambda: sm.Tool("bull", 2.0, -0.1), "corner_radius"),
    (lambda: sm.Tool("flat", 2.0, 0.5), "corner_radius"),
    (lambda: sm.Tool("flat", 0.0), "radius"),
    (lambda: sm.Tool("flat", 1.0, flute_length=0), "flute_length"),
    (lambda: parse_tool("bull:3"), "tool"),
    (lambda: parse_tool("cone:3"), "tool"),
    (lambda: parse_tool("flat:-1"), "radius"),
    (lambda: sm.Tool("ball", 1.0).stepover_for_scallop(1.0), "scallop"),
])
def test_tool_bad_input(make, word):
    with pytest.raises(sm.SurfmodError, match=word):
        make()


def test_tool_table(tmp_path):
    toml = tmp_path / "t.toml"
    toml.write_text('[[tool]]\nnumber = 1\nkind = "flat"\nradius = 3\nflute_length = 25\nspindle = 10000\n'
                    'feed = 900\n\n[[tool]]\nnumber = 2\nkind = "bull"\nradius = 2\ncorner_radius = 0.5\n')
    table = load_tool_table(toml)
    assert table[1].flute_length == 25 and table[1].spindle == 10000 and table[2].corner == 0.5
    js = tmp_path / "t.json"
    js.write_text(json.dumps({"tool": [{"number": 4, "kind": "ball", "radius": 1.5}]}))
    assert load_tool_table(js)[4].corner == 1.5
    js.write_text(json.dumps({"tool": [{"number": 4, "kind": "ball", "radius": 1.5, "colour": 3}]}))
    with pytest.raises(sm.SurfmodError, match="tools"):
        load_tool_table(js)
    filled = sm.Tool("flat", 3.0).with_defaults(1)
    assert filled.number == 1 and filled.spindle > 0 and filled.feed > filled.plunge_feed > 0


@pytest.mark.parametrize("shape", [Ball(2.0), Flat(2.0), Bull(2.0, 0.5)])
@pytest.mark.parametrize("g", [0.01, 0.3])
def test_grown_cutter_is_the_cutters_offset(shape, g):
    """Every point of the grown cutter's end (its tip ``g`` below the cutter's) lies ``g``
    from the cutter's end, in closed form: from its flat core (the segment of height ``g``
    out to ``a = R - c``) or its corner (the quarter circle of radius ``c`` round
    ``(a, g + c)``); the roughing's stand-in holds the grown cutter."""
    grown = shape.grown(g)
    d = np.linspace(0.0, grown.radius, 401)
    z = grown.profile(d)
    a, c = shape.core, shape.corner
    to_core = np.hypot(np.maximum(d - a, 0.0), z - g)
    on_corner = (d >= a) & (z <= g + c)  # where the nearest corner point lies on its quarter
    to_corner = np.where(on_corner, np.abs(np.hypot(d - a, z - g - c) - c), np.inf)
    assert np.abs(np.minimum(to_core, to_corner) - g).max() < 1e-12
    assert grown.radius == shape.radius + g and np.all(shape.roughing_offset(g).profile(d) <= z)
