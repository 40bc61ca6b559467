"""The plane through three points, S(u, v) = P0 + u (P1 - P0) + v (P2 - P0).

OCCT's Geom_Plane uses an orthonormal frame, so surfmod hands OCCT the bilinear
(degree 1 x 1) B-spline that has exactly the lecture's parametrization.
"""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

p0, p1, p2 = np.array([0, 0, 0.0]), np.array([40, 0, 10.0]), np.array([5, 30, 0.0])
s = sm.plane(p0, p1, p2)
print("S(0.5, 0.5) =", s.points(0.5, 0.5), "= P0 + (P1-P0)/2 + (P2-P0)/2 =", p0 + (p1 - p0) / 2 + (p2 - p0) / 2)
print("normal", s.normals(0.5, 0.5), "implicit F at a point:", s.implicit(s.points(0.2, 0.7)))
print(sm.crosscheck(s))
print("m x n mesh (5 x 4):", sm.mesh(s, 5, 4).faces.shape[0], "triangles")

sm.export_step(s, OUT / "plane_three_points.step")
sm.export_stl(s, OUT / "plane_three_points.stl")
