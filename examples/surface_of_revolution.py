"""Surface of revolution: a B-spline vase profile turned 360 degrees about z
(Geom_SurfaceOfRevolution, u = angle, v = profile parameter), its exact NURBS form,
and a revolved solid built with build123d from the same profile."""

from pathlib import Path

import math

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

pts = [(12, 0, 0), (22, 0, 10), (14, 0, 30), (18, 0, 45), (9, 0, 55)]
vase = sm.revolution(sm.BSplineCurve(pts, 3), (0, 0, 0), (0, 0, 1), 360)
nurbs = vase.to_nurbs()
print("revolution", sm.crosscheck(vase))
print("NURBS form", sm.crosscheck(nurbs), f"{nurbs.control_points.shape[:2]} poles")

# closed forms: a revolved line is a cone, a revolved off-axis circle a torus
cone = sm.revolution(sm.Line((10, 0, 0), (4, 0, 12)), (0, 0, 0), (0, 0, 1))
slant = math.hypot(6, 12)
print(f"cone area {cone.face().area:.6f} vs pi (r1 + r2) s = {math.pi * 14 * slant:.6f}")
ring = sm.revolution(sm.Circle((30, 0, 20), (0, 1, 0), 3.0), (0, 0, 0), (0, 0, 1))
print(f"torus area {ring.face().area:.6f} vs 4 pi^2 R r = {4 * math.pi**2 * 30 * 3:.6f}")

edge = bd.Edge.make_spline(pts)
solid = bd.revolve(bd.make_face(bd.Wire([edge, bd.Edge.make_line(pts[-1], (0, 0, 55)),
                                          bd.Edge.make_line((0, 0, 55), (0, 0, 0)),
                                          bd.Edge.make_line((0, 0, 0), pts[0])])), bd.Axis.Z)
sm.export_step([vase.face(), nurbs.face(), ring.face(), solid.translate((60, 0, 0))], OUT / "surface_of_revolution.step")
sm.export_stl(solid, OUT / "surface_of_revolution.stl", tolerance=0.05)
