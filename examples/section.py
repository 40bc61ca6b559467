"""Cross-section views of a part: curves to DXF and SVG, with a PNG preview."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

part = bd.fillet(bd.Box(60, 40, 20).edges().filter_by(bd.Axis.Z), radius=8) - bd.Cylinder(8, 30)
part += bd.Sphere(12).translate((0, 0, 10)) - bd.Cylinder(8, 60)
sm.export_step(part, OUT / "section_part.step")
sm.export_stl(part, OUT / "section_part.stl", tolerance=0.01)

s = sm.section(part, (0, 0, 5), (0, 0, 1))
print(s)
sm.export_dxf(s, OUT / "section_z5.dxf")
sm.export_svg(s, OUT / "section_z5.svg")
s.preview(OUT / "section_z5.png")

oblique = sm.section(part, (0, 0, 0), (1, 0, 1))
print(oblique, "areas", np.round(oblique.areas(), 3))
sm.export_dxf(oblique, OUT / "section_oblique.dxf")

# the lecture's check: a sphere's section is a circle of radius sqrt(R^2 - d^2)
c = sm.section(bd.Sphere(10), (0, 0, 6), (0, 0, 1)).polylines[0]
print("sphere section radius", np.linalg.norm(c[:, :2], axis=1).max(), "expected 8")
