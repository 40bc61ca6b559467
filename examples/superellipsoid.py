"""Superellipsoids from sharp (s = 0.1, nearly a box) through the ellipsoid (s = 1) to
pinched (s = 3): implicit form, parametric form with signed powers and the bicubic
B-spline fit with its stated tolerance."""

from pathlib import Path

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

faces, surfaces = [], []
for k, (s1, s2) in enumerate([(0.1, 0.1), (0.5, 1.0), (1.0, 1.0), (2.0, 0.5), (3.0, 3.0)]):
    s = sm.superellipsoid(10, 8, 6, s1, s2)
    print(f"s1={s1:<4} s2={s2:<4} {s.samples[0]:>3} x {s.samples[1]:<3} samples, "
          f"max deviation {s.max_deviation:.2e} <= tolerance {s.tolerance:.0e}")
    surfaces.append(s.translated((25 * k, 0, 0)))
    faces.append(surfaces[-1].face())

sm.export_step(faces, OUT / "superellipsoid.step")
# the grid mesh of each fitted surface (the lecture's m x n mesh) for the STL
sm.export_stl([sm.mesh(s, 40, 80) for s in surfaces], OUT / "superellipsoid.stl")
