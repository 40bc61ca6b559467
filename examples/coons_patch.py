"""A Coons patch spanned by four boundary curves (build123d edges), as an exact
B-spline; OCCT's GeomFill_BSplineCurves (Coons style) built on the same curves."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm
from surfmod.occ.geom import read_bspline_surface

OUT = Path(__file__).resolve().parent.parent / "step_samples"

# a saddle-like frame: four splines meeting at the corners (OCCT's Coons style needs
# polynomial curves with at least 4 poles; sm.coons also takes arcs and lines)
c0 = bd.Edge.make_spline([(0, 0, 0), (12, -4, 3), (28, -3, 2), (40, 0, 0)])
c1 = bd.Edge.make_spline([(0, 30, 5), (20, 34, 9), (40, 30, 5)])
d0 = bd.Edge.make_spline([(0, 0, 0), (-3, 10, 4), (-2, 20, 2), (0, 30, 5)])
d1 = bd.Edge.make_spline([(40, 0, 0), (43, 15, -4), (40, 30, 5)])

linear = sm.coons(c0, c1, d0, d1)                   # bilinearly blended
hermite = sm.coons(c0, c1, d0, d1, blend="hermite")  # OCCT's GeomFill_Coons blending
occt = read_bspline_surface(hermite.occt_fill())
print("bilinear Coons:", linear)
print("hermite vs OCCT GeomFill_BSplineCurves, max pole difference:",
      f"{np.abs(occt['control_points'] - hermite.control_points).max():.1e}")
print("crosscheck:", sm.crosscheck(linear, samples=12))
(u0, u1), (v0, v1) = linear.domain
mid = linear.points((u0 + u1) / 2, (v0 + v1) / 2)
print("centre of the bilinear patch:", mid.round(4), "| hermite:", hermite.points((u0 + u1) / 2, (v0 + v1) / 2).round(4))

sm.export_step([linear.face(), hermite.face().translate((50, 0, 0))], OUT / "coons_patch.step")
