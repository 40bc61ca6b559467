"""Tabulated cylinder: a planar spline translated along a slanted direction
(Geom_SurfaceOfLinearExtrusion, the face BRepPrimAPI_MakePrism builds), closed into a
solid with build123d."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

profile = bd.Edge.make_spline([(0, 0, 0), (10, 8, 0), (20, -4, 0), (30, 5, 0)])
wall = sm.tabulated_cylinder(profile, (0.2, 0.0, 1.0), 25.0)
print(sm.crosscheck(wall))
print("S(u, v) = C(u) + v D:", wall.points(0.0, 25.0), "=", wall.curve.points(0.0) + 25.0 * wall.direction)

# algebra mode: a 2 mm wall from the sheet, and a plain cylinder from a circle
sheet = bd.thicken(wall.face(), 2.0)
tube = sm.tabulated_cylinder(sm.Circle((15, 30, 0), (0, 0, 1), 6.0), (0, 0, 1), 25.0)
print("tube", sm.crosscheck(tube), f"area {tube.face().area:.3f}")
sm.export_step([wall.face(), tube.face(), sheet], OUT / "tabulated_cylinder.step")
sm.export_stl(sheet, OUT / "tabulated_cylinder.stl", tolerance=0.05)
