"""Quadrics: sphere and torus in OCCT's own parametrization, the ellipsoid as an exact
rational B-spline; implicit forms F(x, y, z) = 0 checked on evaluated points."""

from pathlib import Path

import math

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

shapes = {
    "sphere": sm.sphere(10.0, center=(0, 0, 10)),
    "torus": sm.torus(12.0, 3.0, center=(40, 0, 0), axis=(0, 1, 1)),
    "ellipsoid": sm.ellipsoid(15.0, 9.0, 6.0, center=(0, 40, 0)),
}
for name, s in shapes.items():
    (u0, u1), (v0, v1) = s.domain
    f = s.implicit(s.grid(np.linspace(u0, u1, 40), np.linspace(v0, v1, 40)))
    print(f"{name:10s} {sm.crosscheck(s)}  max |F| on points = {np.abs(f).max():.1e}")
print(f"sphere area {shapes['sphere'].face().area:.6f} vs 4 pi R^2 = {4 * math.pi * 100:.6f}")
print(f"torus area  {shapes['torus'].face().area:.6f} vs 4 pi^2 R r = {4 * math.pi**2 * 36:.6f}")
print(f"ellipsoid volume 4/3 pi abc = {shapes['ellipsoid'].volume():.3f}")

# the faces are ordinary build123d faces: cut the sphere with a box in algebra mode
ball = bd.Solid.make_sphere(10).translate((0, 0, 10)) - bd.Box(30, 30, 10, align=bd.Align.MIN).translate((0, 0, 15))
sm.export_step([s.face() for s in shapes.values()] + [ball.translate((-40, 0, 0))], OUT / "quadrics.step")
sm.export_stl([s.face() for s in shapes.values()], OUT / "quadrics.stl", tolerance=0.05)
