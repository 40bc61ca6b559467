"""Trimming a NURBS patch by loops in its (u, v) parameter space: an elliptical outer
boundary with a circular hole (an exact rational p-curve).  The trimmed build123d face's
area from OCCT's BRepGProp is compared with the NumPy Green's-theorem quadrature.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm
from surfmod.occ.properties import gprops

OUT = Path(__file__).resolve().parent.parent / "step_samples"

x, y = np.meshgrid(np.linspace(0, 40, 6), np.linspace(0, 30, 5), indexing="ij")
z = 5 + 3 * np.sin(x / 9) * np.cos(y / 8)
patch = sm.BSplineSurface(np.stack([x, y, z], -1), (3, 2), None, 1 + 0.5 * np.cos(x / 7) ** 2)

th = np.linspace(0, 2 * np.pi, 61)
outer = np.c_[0.5 + 0.42 * np.cos(th), 0.5 + 0.4 * np.sin(th)]
outer[-1] = outer[0]
# exact circle of radius 0.12 around (0.55, 0.5) as a rational quadratic curve in z = 0
c = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
hole = sm.BSplineCurve(
    np.c_[0.55 + 0.12 * c[:, 0], 0.5 + 0.12 * c[:, 1], np.zeros(9)],
    2,
    [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
    [1, 2**-0.5] * 4 + [1],
)

face = sm.trim(patch, [outer, hole])
occ_area = gprops(face.wrapped, 1e-10)["area"]  # BRepGProp at relative accuracy 1e-10
np_area = sm.trimmed_area(patch, [outer, hole])
print(f"trimmed area: OCCT {occ_area:.10f}, NumPy {np_area:.10f}, rel. diff {abs(occ_area - np_area) / np_area:.1e}")

part = bd.thicken(face, 1.0)
sm.export_step([face, part], OUT / "trim.step")
sm.export_stl(part, OUT / "trim.stl", tolerance=0.02)
