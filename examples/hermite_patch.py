"""Hermite bicubic patch from corners, tangents and twists (the lecture's S M B M^T T^T).

The patch is converted exactly to a cubic Bézier patch (c1 = p0 + d0/3, c2 = p1 - d1/3
in each direction) and handed to OCCT as a Geom_BezierSurface.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

corners = np.array([[[0, 0, 0], [0, 30, 5]], [[40, 0, 5], [40, 30, 0]]], dtype=float)
du = np.array([[[40, 0, 20], [40, 0, -10]], [[40, 0, -20], [40, 0, 10]]], dtype=float)  # dS/ds
dv = np.array([[[0, 30, 15], [0, 30, -15]], [[0, 30, 0], [0, 30, 10]]], dtype=float)  # dS/dt
twist = np.zeros((2, 2, 3))
patch = sm.HermiteBicubic(corners, du, dv, twist)

print("corner (1, 1):", patch.points(1.0, 1.0), "tangent dS/ds there:", patch.derivatives(1.0, 1.0)[1, 0])
print("Bézier control points of the equivalent patch:\n", patch.control_points.round(3))
print(sm.crosscheck(patch))

with bd.BuildPart() as builder:  # build123d builder mode: thicken the patch face
    bd.thicken(patch.face(), 1.5)  # operations add to the active builder
part = builder.part
print(f"part volume {part.volume:.1f}")

sm.export_step([patch, part], OUT / "hermite_patch.step")
sm.export_stl(part, OUT / "hermite_patch.stl")
