"""Filling holes between faces with G1: the three-sided corner of three fillets and a
four-sided hole in a NURBS skin, beside OCCT's BRepOffsetAPI_MakeFilling."""

from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm
from surfmod.construct.fill import occt_fill
from surfmod.gallery.synthetic import wavy_net

OUT = Path(__file__).resolve().parent.parent / "step_samples"

r = 2.0
fillets = [(sm.CylindricalSurface(r, (0, 0, 0), axis, x_dir, u_range=(0, np.pi / 2), v_range=(-6, 0)), "v1")
           for axis, x_dir in (((1, 0, 0), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)), ((0, 0, 1), (1, 0, 0)))]
corner = sm.fill(fillets)
angles = []
for patch in corner:            # each patch has two sides on two of the fillets
    for fillet, _ in fillets:
        try:
            angles.append(sm.continuity(patch, fillet).g1)
        except sm.SurfmodError:  # this fillet does not border this patch
            pass
worst = max(angles)
print(f"3-sided corner: {len(corner)} patches, worst normal angle {worst:.2e} rad")
sm.export_step(bd.Compound([s.face() for s, _ in fillets] + corner.faces()), OUT / "fill_corner.step")

skin = sm.BSplineSurface(wavy_net(7, 7, 0.4))
pieces = {(i, j): skin.segment(u, v) for i, u in enumerate(((0, .35), (.35, .65), (.65, 1)))
          for j, v in enumerate(((0, .35), (.35, .65), (.65, 1)))}
hole = [(pieces[1, 0], "v1"), (pieces[2, 1], "u0"), (pieces[1, 2], "v0"), (pieces[0, 1], "u1")]
ours = sm.fill(hole)
theirs = occt_fill(hole)
for name, face in (("sm.fill", ours[0]), ("MakeFilling", theirs)):
    angles = [sm.continuity(s, face).g1 for s, _ in hole]
    print(f"4-sided hole, {name:11s}: worst normal angle {max(angles):.2e} rad")
sm.export_step(bd.Compound([p.face() for p, _ in hole] + ours.faces()), OUT / "fill_hole.step")
