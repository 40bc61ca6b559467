"""A Gordon surface through a network of profile and guide curves (build123d splines of
a wavy hull bottom), beside build123d's own Face.make_gordon_surface."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"


def hull(x, y):
    return 4 * np.sin(np.pi * x / 60) * (1 - (y / 12) ** 2) + 0.05 * x


def spline(pts):
    return bd.Edge.make_spline([bd.Vector(*p) for p in pts])


xs, ys = (0, 15, 30, 45, 60), (-12, -4, 4, 12)
profiles = [spline([(x, y, hull(x, y)) for x in np.linspace(0, 60, 13)]) for y in ys]
guides = [spline([(x, y, hull(x, y)) for y in np.linspace(-12, 12, 9)]) for x in xs]

tol = 1e-3
ours = sm.gordon(profiles, guides, tol)
print(f"sm.gordon: {ours.control_points.shape[0]}x{ours.control_points.shape[1]} poles, degree {ours.degree},",
      f"network on the surface within {ours.network_deviation():.1e} (OCCT projection)")
theirs = ours.occt_gordon()
print("build123d Face.make_gordon_surface built as well:", type(theirs).__name__)
print("crosscheck:", sm.crosscheck(ours, samples=12))

sm.export_step([ours.face(), theirs.translate((0, 30, 0))], OUT / "gordon_network.step")
