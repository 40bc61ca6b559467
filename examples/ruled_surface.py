"""Ruled surface between a B-spline rail and a circular arc, build123d style.

Both curves become compatible B-splines (degree elevation + knot merging, as OCCT's
GeomFill does); the surface is checked pole for pole against GeomFill::Surface and the
faces are sewn into a build123d shell.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

rail = sm.BSplineCurve([(0, 0, 0), (15, 20, 0), (30, -10, 0), (50, 10, 0)], 3)
arc = sm.Arc((25, 10, 30), (0, 0, 1), 20.0, 180, 360)
# any build123d edge works too:
edge = bd.Edge.make_spline([(0, 0, 60), (20, 15, 55), (50, 0, 60)])

lower = sm.ruled(rail, arc)
upper = sm.ruled(arc, edge)
for s in (lower, upper):
    (u0, u1), _ = s.domain
    u = np.linspace(u0, u1, 5)
    print(f"degree {s.degree}, {sm.crosscheck(s)}")
    occ = s.occt_ruled()
    dev = max(np.abs(s.points(t, 0.5) - np.array(occ.Value(t, 0.5).Coord())).max() for t in u)
    print(f"  vs GeomFill::Surface at v=0.5: {dev:.2e}")

# algebra mode: the two ruled faces share the arc, sew them into one shell
shell = bd.Shell([lower.face(), upper.face()])
print(f"shell area {shell.area:.3f} = {lower.face().area:.3f} + {upper.face().area:.3f}")
sm.export_step([lower.face(), upper.face()], OUT / "ruled_surface.step")
sm.export_stl([lower.face(), upper.face()], OUT / "ruled_surface.stl", tolerance=0.05)
