"""Twisted swept surface: a flat blade swept up a curved path while turning 180 degrees
about the path tangent (linear twist law), like a twisted ribbon or a drill flute."""

from pathlib import Path

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

path = sm.BSplineCurve([(0, 0, 0), (0, 0, 20), (10, 5, 40), (30, 0, 50)], 3)
blade = sm.Line((-8, 0, 0), (8, 0, 0))

s = sm.sweep(blade, path, mode="corrected_frenet", twist=180.0)
print(sm.crosscheck(s, samples=16))
end_frame = s.frames(s.domain[1][1])
print("end normal", end_frame[:, 1].round(3))
sm.export_step(s, OUT / "sweep_twisted.step")
sm.export_stl(s, OUT / "sweep_twisted.stl", tolerance=0.05)
