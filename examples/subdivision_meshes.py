"""Subdivision meshes: Loop on a triangle cage, Catmull–Clark on mixed polygons with a
sharp crease, and an open quad cage whose limit becomes an exact B-spline shell.

Writes STL meshes and one STEP shell into step_samples/.
"""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

# Loop subdivision of an octahedron: a sphere-like limit surface
octa_v = 10.0 * np.array([(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)], dtype=float)
octa_f = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4), (1, 0, 5), (2, 1, 5), (3, 2, 5), (0, 3, 5)]
loop = sm.loop_subdivide(octa_v, octa_f, levels=4)
limit = sm.loop_limit(octa_v, octa_f)
print(f"Loop x4: {len(loop.faces)} triangles, watertight {loop.to_trimesh().is_watertight}, "
      f"limit of vertex 0 at {np.round(limit.positions[0], 4)}")
sm.export_stl(loop, OUT / "subdivision_loop_octahedron.stl")

# Catmull–Clark of a pentagonal prism (two pentagons + five quads), top rim kept sharp
a = 2 * np.pi * np.arange(5) / 5
ring = np.stack([8 * np.cos(a), 8 * np.sin(a), np.zeros(5)], 1)
prism_v = np.concatenate([ring, ring + [0, 0, 12]])
prism_f = [[4, 3, 2, 1, 0], [5, 6, 7, 8, 9]] + [[i, (i + 1) % 5, 5 + (i + 1) % 5, 5 + i] for i in range(5)]
rim = [(5 + i, 5 + (i + 1) % 5) for i in range(5)]
cc = sm.catmull_clark(prism_v, prism_f, levels=3, creases=rim)
print(f"Catmull-Clark x3 with a crease: {len(cc.faces)} quads, watertight {cc.to_trimesh().is_watertight}")
sm.export_stl(cc, OUT / "subdivision_cc_prism_crease.stl")

# an open 6 x 5 cage: boundary curve rule + interpolated corners = an exact B-spline shell
i, j = np.meshgrid(np.arange(6), np.arange(5), indexing="ij")
grid_v = np.stack([4.0 * i, 4.0 * j, 3 * np.sin(i * 0.9) * np.cos(j * 0.7)], -1).reshape(-1, 3)
grid_f = [(p * 5 + q, (p + 1) * 5 + q, (p + 1) * 5 + q + 1, p * 5 + q + 1) for p in range(5) for q in range(4)]
shell = sm.limit_surface(grid_v, grid_f, levels=0)
print(shell, "open:", shell.open)
sm.export_step(shell, OUT / "subdivision_open_grid.step")
