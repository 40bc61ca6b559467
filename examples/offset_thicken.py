"""Offsets that say in advance where they fail, and a thickened NURBS shell, build123d style."""

from pathlib import Path

import surfmod as sm
from surfmod.gallery.synthetic import wavy_net
from surfmod.occ.properties import gprops

OUT = Path(__file__).resolve().parent.parent / "step_samples"

skin = sm.BSplineSurface(wavy_net(7, 6, 0.5))
outer = sm.offset(skin, 0.8, tolerance=1e-5)
print(f"offset 0.8: {outer.control_points.shape[0]} x {outer.control_points.shape[1]} poles, "
      f"max deviation {outer.max_deviation:.2e}")
try:
    sm.offset(skin, -4.0, tolerance=1e-5)
except sm.SurfmodError as exc:
    print(f"refused: {exc}")

shell = sm.thicken(skin, 0.8)
print(f"thickened: volume {gprops(shell.wrapped)['volume']:.6f} (BRepGProp), "
      f"{sm.mass_properties(shell).volume:.6f} (NumPy quadrature)")
sm.export_step([skin.face(), outer.face()], OUT / "offset_surfaces.step")
sm.export_step(shell, OUT / "thickened_shell.step")
