"""General B-spline and NURBS surfaces: non-uniform knots, repeated knots, weights.

Shows the knot-vector conventions (full vectors, as in the textbook), knot insertion and
Bézier extraction (exact), and that a weight pulls the surface towards its control point.
"""

from pathlib import Path

import numpy as np

import surfmod as sm
from surfmod.nets.bezier import bezier_patches

OUT = Path(__file__).resolve().parent.parent / "step_samples"

x, y = np.meshgrid(np.linspace(0, 50, 7), np.linspace(0, 40, 6), indexing="ij")
net = np.stack([x, y, 5 * np.sin(x / 10) + 3 * np.cos(y / 8)], axis=-1)
U = [0, 0, 0, 0, 0.25, 0.5, 0.5, 1, 1, 1, 1]  # cubic, a double knot at 0.5 (C1 there)
V = [0, 0, 0, 0.3, 0.6, 0.8, 1, 1, 1]  # quadratic
bspline = sm.BSplineSurface(net, (3, 2), (U, V))

w = np.ones(net.shape[:2])
w[3, 2] = 8.0  # a heavy weight pulls the surface towards P[3, 2]
nurbs = sm.BSplineSurface(net, (3, 2), (U, V), weights=w)
u, v = 0.5, 0.45
print("pull towards P[3,2]:", np.linalg.norm(bspline.points(u, v) - net[3, 2]), "->",
      np.linalg.norm(nurbs.points(u, v) - net[3, 2]))

for s in (bspline, nurbs):
    print(s, sm.crosscheck(s))

refined = nurbs.insert_knot(u=0.7, v=0.45)
print("after knot insertion, same surface:", np.abs(refined.grid(np.linspace(0, 1, 9), np.linspace(0, 1, 9))
                                                    - nurbs.grid(np.linspace(0, 1, 9), np.linspace(0, 1, 9))).max())
print("Bézier patches:", len(bezier_patches(nurbs)))

k = nurbs.curvatures(0.5, 0.45)
print(f"at (0.5, 0.45): Gaussian {k.gaussian:.3e}, mean {k.mean:.3e}")

sm.export_step([bspline, nurbs.translated((0, 0, 20))], OUT / "bspline_nurbs.step")
sm.export_stl([bspline, nurbs.translated((0, 0, 20))], OUT / "bspline_nurbs.stl")
