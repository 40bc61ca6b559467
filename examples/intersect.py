"""Surface-surface, surface-plane and line-surface intersection by marching on the NumPy
evaluator, cross-checked against OCCT's GeomAPI_IntSS / GeomAPI_IntCS.
"""

import sys
from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

# OCCT's side of the cross-check: a twin kept with the tests (tests/twins), not in the package
sys.path.append(str(Path(__file__).resolve().parent.parent / "tests"))
from twins.geomapi import intersect_line, intersect_surfaces  # noqa: E402


OUT = Path(__file__).resolve().parent.parent / "step_samples"

rng = np.random.default_rng(0)
x, y = np.meshgrid(np.linspace(0, 4, 7), np.linspace(0, 3, 6), indexing="ij")
a = sm.BSplineSurface(np.stack([x, y, rng.uniform(-1, 1, (7, 6))], -1), (3, 3), None, rng.uniform(0.5, 2, (7, 6)))
x, y = np.meshgrid(np.linspace(-0.5, 4.5, 6), np.linspace(-0.5, 3.5, 6), indexing="ij")
b = sm.BSplineSurface(np.stack([x, y, 0.3 * np.sin(x * 2) + 0.2 * y - 0.3], -1), (3, 3))

curves = sm.intersect(a, b)
theirs = intersect_surfaces(a.geom(), b.geom())
print(f"surface-surface: {len(curves)} curves (OCCT IntSS: {len(theirs)})")
for c in curves:
    gap = np.abs(b.points(c.uv_b[:, 0], c.uv_b[:, 1]) - c.points).max()
    match = min((abs(L - c.length) for _, L in theirs), default=np.inf)
    occt = f"|dL| to OCCT {match:.1e}" if match < 1e-4 * c.length else "not reported by OCCT IntSS"
    print(f"  {len(c)} points, closed={c.closed}, length {c.length:.8f}, |A-B| {gap:.1e}, {occt}")

plane = ((2, 1.5, 0.1), (0.3, 0.2, 1.0))
for c in sm.intersect(a, plane):
    print(f"surface-plane: length {c.length:.8f}")

hits = sm.intersect_line(a, (2, 1.5, 3), (0.1, 0.2, -1))
print("line hits (u, v, t):", hits, "OCCT IntCS:", intersect_line(a.geom(), (2, 1.5, 3), np.array((0.1, 0.2, -1)) / np.linalg.norm((0.1, 0.2, -1))))

edges = [bd.Edge.make_spline([bd.Vector(*p) for p in c.points[:: max(1, len(c) // 60)]]) for c in curves if not c.closed]
sm.export_step([a.face(), b.face(), *edges], OUT / "intersect.step")
