"""Closest-point projection of many points and of a curve onto a NURBS patch (vectorized
Newton, equal to GeomAPI_ProjectPointOnSurf), and the shadow of the patch on a plane
under parallel light (projected boundary + silhouettes + outline).
"""

import sys
from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

# OCCT's side of the cross-check: a twin kept with the tests (tests/twins), not in the package
sys.path.append(str(Path(__file__).resolve().parent.parent / "tests"))
from twins.geomapi import project_points  # noqa: E402


OUT = Path(__file__).resolve().parent.parent / "step_samples"

rng = np.random.default_rng(0)
x, y = np.meshgrid(np.linspace(0, 4, 7), np.linspace(0, 3, 6), indexing="ij")
s = sm.BSplineSurface(np.stack([x, y, 1.5 * rng.uniform(-1, 1, (7, 6))], -1), (3, 3), None, rng.uniform(0.5, 2, (7, 6)))

pts = np.c_[rng.uniform(0.3, 3.7, 2000), rng.uniform(0.3, 2.7, 2000), rng.uniform(-2, 2, 2000)]
pr = sm.project(pts, s)
theirs = project_points(s.geom(), (0, 1, 0, 1), pts[:200])
same = np.abs(pr.distance[:200] - theirs[:, 2]) < 1e-9
print(f"projected 2000 points; first 200 vs OCCT: {same.sum()} equal, max |du| {np.abs(pr.u[:200][same] - theirs[same, 0]).max():.1e}, "
      f"{(~same).sum()} closer boundary points (OCCT only gives orthogonal projections)")

curve = sm.BSplineCurve([(0.5, 0.5, 3.0), (2.0, 1.0, 2.5), (3.5, 2.5, 3.0)], 2)
print("curve projection distances:", np.round(sm.project(curve, s, samples=5).distance, 4))

sh = sm.shadow(s, (0.5, 0.3, -1.0), ((0, 0, -2), (0, 0.2, 1)))
print(f"shadow: {len(sh.silhouettes)} silhouette curves, {len(sh.outline)} outline loop(s), area {sh.area:.6f}, complete={sh.complete}")

outline = [bd.Wire.make_polygon([bd.Vector(*p) for p in loop[:-1]]) for loop in sh.outline]
sm.export_step([s.face(), *outline], OUT / "project_shadow.step")
