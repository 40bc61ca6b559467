"""Interference between mating parts: a shaft in a bored block, with and without clearance."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

block = bd.Box(40, 40, 20) - bd.Cylinder(10.0, 30)
for shaft_radius in (9.9, 10.0, 10.2):  # clearance fit, line-to-line, interference fit
    shaft = bd.Cylinder(shaft_radius, 40)
    r = sm.interference(block, shaft)
    print(f"shaft r={shaft_radius}:\n{r}\n")

pin = bd.Sphere(5).translate((0, 0, 17))
print(sm.interference(block, pin))
sm.export_step([block, bd.Cylinder(10.2, 40), pin], OUT / "interference.step")
sm.export_stl(block, OUT / "interference.stl", tolerance=0.01)
