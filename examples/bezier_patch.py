"""Bézier patch (Bernstein basis), thickened into a shell part, build123d style.

The 5 x 4 control net is the lecture's Bézier surface of degree (4, 3); its face is
cross-checked against OCCT's Geom_BezierSurface and drops straight into build123d.
"""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"

x, y = np.meshgrid(np.linspace(0, 40, 5), np.linspace(0, 30, 4), indexing="ij")
z = 20 + 4 * np.sin(x / 12) * np.cos(y / 10)
patch = sm.BezierSurface(np.stack([x, y, z], axis=-1))
print(f"degree {patch.degree}: {sm.crosscheck(patch)}")

part = bd.thicken(patch.face(), 2.0)  # build123d algebra mode: a 2 mm thick shell
print(f"shell part volume {part.volume:.1f} (area x thickness ~ {patch.face().area * 2:.1f})")

sm.export_step([patch.face(), part], OUT / "bezier_patch.step")
sm.export_stl(part, OUT / "bezier_patch.stl", tolerance=0.01)
