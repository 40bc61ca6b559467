"""Any STEP face read back: build123d primitives (box, cylinder, cone, sphere, torus,
fillets, a revolved and an extruded spline) exported to STEP, read face by face with
sm.from_face and cross-checked against OCCT."""

from collections import Counter
from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

with bd.BuildPart() as vase:
    with bd.BuildSketch(bd.Plane.XZ):
        with bd.BuildLine():
            bd.Spline((20, 0), (30, 10), (25, 20), (30, 30))
            bd.Polyline((30, 30), (15, 30), (15, 0), (20, 0))
        bd.make_face()
    bd.revolve(axis=bd.Axis.Z, revolution_arc=270)
with bd.BuildPart() as wave:
    with bd.BuildSketch():
        with bd.BuildLine():
            bd.Spline((0, 0), (10, 10), (20, 5), (30, 10))
            bd.Polyline((30, 10), (30, -10), (0, -10), (0, 0))
        bd.make_face()
    bd.extrude(amount=20)

parts = [
    bd.fillet(bd.Box(30, 30, 20).edges(), 4),
    bd.Cylinder(10, 30).translate((50, 0, 0)),
    bd.Cone(15, 5, 25).translate((100, 0, 0)),
    bd.Sphere(12).translate((0, 60, 0)),
    bd.Torus(20, 5).translate((60, 60, 0)),
    vase.part.translate((0, 130, 0)),
    wave.part.translate((80, 130, 0)),
]
path = OUT / "read_back_primitives.step"
sm.export_step(parts, path)

shape = bd.import_step(str(path))
kinds, worst = Counter(), 0.0
for face in shape.faces():
    s = sm.from_face(face)
    r = sm.crosscheck(face, samples=16)
    assert r.passed, (type(s.surface).__name__, r)
    kinds[type(s.surface).__name__] += 1
    worst = max(worst, r.max_deviation)
print(f"{len(shape.faces())} faces read back, max deviation {worst:.2e}")
for name, n in sorted(kinds.items()):
    print(f"  {name:20s} {n}")
