"""Curves as inputs: Circle, Arc (also through three points), Ellipse in OCCT's angle
parametrization, and their exact rational quadratic B-spline forms."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

circle = sm.Circle((0, 0, 0), (0, 0, 1), 10.0)
arc = sm.Arc.through((30, 0, 0), (40, 10, 0), (50, 0, 0))
ellipse = sm.Ellipse((0, 40, 0), (0, 0, 1), 15.0, 6.0)
for c in (circle, arc, ellipse):
    nurbs = c.to_bspline()
    t = np.linspace(*nurbs.domain, 2001)
    print(f"{type(c).__name__:8s} {sm.crosscheck(c)}; NURBS: {nurbs.control_points.shape[0]} poles, "
          f"max |F| on NURBS points {np.abs(c.implicit(nurbs.points(t))).max():.1e}")

# the curves are build123d edges: a slot profile extruded in algebra mode
slot = bd.Wire([sm.Arc((0, -60, 0), (0, 0, 1), 5, 90, 270).edge(), bd.Edge.make_line((0, -65, 0), (20, -65, 0)),
                sm.Arc((20, -60, 0), (0, 0, 1), 5, -90, 90).edge(), bd.Edge.make_line((20, -55, 0), (0, -55, 0))])
part = bd.extrude(bd.Face(slot), amount=4)
print(f"slot volume {part.volume:.4f} vs {4 * (20 * 10 + np.pi * 25):.4f}")
sm.export_step([circle.edge(), arc.edge(), ellipse.edge(), part], OUT / "conics.step")
sm.export_stl(part, OUT / "conics.stl", tolerance=0.01)
