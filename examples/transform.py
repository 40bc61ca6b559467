"""Transforms through the control points: translate, rotate, mirror, scale (uniform and
non-uniform) a NURBS patch and compare each with OCCT's gp_Trsf / gp_GTrsf applied to
geom(); then split it into exact pieces by knot insertion (= OCCT's Segment).
"""

import sys
from pathlib import Path

import numpy as np

import surfmod as sm
from surfmod.occ.sample import surface_d0

# OCCT's side of the cross-check: a twin kept with the tests (tests/twins), not in the package
sys.path.append(str(Path(__file__).resolve().parent.parent / "tests"))
from twins.transformed import geom_gtransformed, geom_transformed, named_trsf  # noqa: E402

OUT = Path(__file__).resolve().parent.parent / "step_samples"

x, y = np.meshgrid(np.linspace(0, 40, 6), np.linspace(0, 30, 5), indexing="ij")
z = 5 + 3 * np.sin(x / 9) * np.cos(y / 8)
w = 1 + 0.5 * np.cos(x / 7) ** 2
patch = sm.BSplineSurface(np.stack([x, y, z], -1), (3, 2), None, w)

uu, vv = (a.ravel() for a in np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij"))
cases = {
    "translated": (patch.translated((50, 0, 0)), named_trsf("translation", (50, 0, 0))),
    "rotated": (patch.rotated((0, 0, 0), (0, 0, 1), 30), named_trsf("rotation", (0, 0, 0), (0, 0, 1), 30)),
    "mirrored": (patch.mirrored((0, 0, 0), (0, 1, 0)), named_trsf("mirror", (0, 0, 0), (0, 1, 0))),
    "scaled": (patch.scaled(0.5, (20, 15, 0)), named_trsf("scale", (20, 15, 0), 0.5)),
}
for name, (mine, trsf) in cases.items():
    theirs = geom_transformed(patch.geom(), trsf)
    dev = np.abs(mine.points(uu, vv) - surface_d0(theirs, uu, vv)).max()
    print(f"{name:10s} max deviation from gp_Trsf: {dev:.2e}")

m = np.diag([1.0, 2.0, 0.5, 1.0])
stretched = patch.scaled((1.0, 2.0, 0.5))
dev = np.abs(stretched.points(uu, vv) - surface_d0(geom_gtransformed(patch.geom(), m), uu, vv)).max()
print(f"non-uniform scale max deviation from gp_GTrsf: {dev:.2e}")

pieces = patch.split(u=0.4, v=0.5)
print("split domains:", [p.domain for p in pieces])

faces = [c[0].face() for c in cases.values()] + [stretched.translated((0, 80, 0)).face()]
faces += [p.translated((0, -50, 0)).face() for p in pieces]
sm.export_step(faces, OUT / "transform.step")
