"""Swept surface with a changing profile: the start section blends into a smaller,
turned end section along the path (OCCT: a pipe shell with two sections)."""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

path = sm.BSplineCurve([(0, 0, 0), (0, 0, 20), (15, 5, 40), (40, 0, 45)], 3)
start = sm.BSplineCurve([(-5, -5, 0), (0, -7.5, 0), (5, -5, 0), (7.5, 0, 0), (5, 5, 0)], 3)

# the end section: the start section carried to the path end by the frame, half size
frames = sm.sweep(start, path).frames(np.array([0.0, 1.0]))
m = np.eye(4)
m[:3, :3] = 0.5 * frames[1] @ frames[0].T
m[:3, 3] = path.points(1.0) - m[:3, :3] @ path.points(0.0)
end = start.transformed(m)

s = sm.sweep(start, path, end_profile=end)
print(sm.crosscheck(s, samples=16))
sm.export_step(s, OUT / "sweep_changing_profile.step")
sm.export_stl(s, OUT / "sweep_changing_profile.stl", tolerance=0.05)
