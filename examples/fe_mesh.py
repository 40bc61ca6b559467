"""Finite element meshes of a part: tetrahedra and triangles with gmsh, written via meshio."""

from pathlib import Path

import build123d as bd

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

part = bd.fillet(bd.Box(60, 40, 20).edges().filter_by(bd.Axis.Z), radius=8) - bd.Cylinder(8, 30)
sm.export_step(part, OUT / "fe_part.step")

tets = sm.fe_mesh(part, size=4.0, order=1, kind="volume", path=OUT / "fe_part.vtu")
print(tets)
print(f"mesh volume {tets.volume:.3f} vs solid {sm.mass_properties(part).volume:.3f}")
sm.export_fe_mesh(tets, OUT / "fe_part.inp")

tris = sm.fe_mesh(part, size=4.0, order=2, kind="surface", path=OUT / "fe_part_surface.msh")
print(tris)
print(f"curved (order 2) surface area {tris.quality['measure']:.4f} vs exact {part.area:.4f}")
sm.export_stl(part, OUT / "fe_part.stl", tolerance=0.01)
