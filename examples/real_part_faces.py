"""Faces of a real part are trimmed surfaces: a plate with a hole written to STEP, its top
face read back with sm.from_face, its area, a plane cut clipped to the face, a distance
to the face, and a section of the part as a DXF of exact lines and circles."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

plate = bd.Box(40, 30, 10) - bd.Cylinder(5, 20)
step = OUT / "plate_with_hole.step"
sm.export_step(plate, step)

part = sm.import_step(step)
top = sm.from_face(part.faces().sort_by(bd.Axis.Z)[-1])
print(f"top face: {type(top.surface).__name__} over u {top.domain[0]}, v {top.domain[1]}")
print(f"  area {top.area():.9f} (40 x 30 - pi 5^2 = {1200 - np.pi * 25:.9f}); untrimmed {40 * 30}")

cut = sm.intersect(top, ((0, 0, 0), (1, 0, 0)))  # the plane x = 0 crosses the hole
print(f"  plane x = 0 meets the face in {len(cut)} pieces, {sum(c.length for c in cut):.9f} long (30 - 10)")

above_hole = sm.project([(0, 0, 20)], top)
print(f"  distance from (0, 0, 20) to the face {above_hole.distance[0]:.9f} (to the hole's rim)")

section = sm.section(part, (0, 0, 0), (0, 0, 1))
n = sm.export_dxf(section, OUT / "plate_with_hole_section.dxf")
print(f"section: {section}; {n} exact DXF entities")
