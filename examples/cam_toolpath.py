"""End-to-end CAM: a NURBS surface -> a solid -> STL + G-code for a ball-end mill.

The ball-end mill (with its shank) is dropped onto every face of the solid, walls
included; every straight G1 move of the zig-zag is checked along its length and refined
where it would cut deeper than a tenth of the scallop, so the G-code never gouges.
"""

from pathlib import Path

import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

# 1. a rational bicubic NURBS "mould" surface over 80 x 60 mm
n, p = 7, 3
k = np.concatenate([[0] * p, np.linspace(0, 1, n - p + 1), [1] * p])
g = np.array([k[i + 1:i + p + 1].mean() for i in range(n)])
x, y = 80 * g[:, None], 60 * g[None, :]
z = 20 + 6 * np.sin(np.pi * g[:, None]) * np.sin(np.pi * g[None, :]) - 3 * np.cos(3 * g[:, None])
net = np.stack(np.broadcast_arrays(x, y, z), -1)
weights = np.ones((n, n))
weights[3, 3] = 2.0
top = sm.BSplineSurface(net, (p, p), (k, k), weights)

# 2. close it into a solid: ruled side walls down to a flat bottom
bot = net.copy()
bot[..., 2] = 0
sides = [sm.BSplineSurface(np.stack([a, b]), (1, p), ([0, 0, 1, 1], k), np.stack([wa, wa]))
         for a, b, wa in [(net[0], bot[0], weights[0]), (net[-1], bot[-1], weights[-1]),
                          (net[:, 0], bot[:, 0], weights[:, 0]), (net[:, -1], bot[:, -1], weights[:, -1])]]
solid = sm.make_solid([top, sm.plane((0, 0, 0), (80, 0, 0), (0, 60, 0)), *sides])
print(sm.mass_properties(solid))
sm.export_step(solid, OUT / "cam_part.step")
sm.export_stl(solid, OUT / "cam_part.stl", tolerance=0.01)

# 3. finishing path over the whole solid: 6 mm ball-end mill, 0.05 mm scallop, zig-zag
#    along x; no move cuts deeper than 0.005 mm (a tenth of the scallop) anywhere
tool = sm.Tool("ball", 3.0)
path = sm.toolpath(solid, tool, scallop=0.05, step=1.5)
print(path)
sm.export_gcode(path, OUT / "cam_part.nc", feed=1200, safe_height=40)
print("G-code:", (OUT / "cam_part.nc").read_text().splitlines()[3:10])

# 4. cutter locations on the exact faces: a 10 mm flat end mill dropped at a few points,
#    its mesh heights polished by Newton on the faces themselves (rim or bottom contact)
from surfmod.cam.toolpath import drop_cutter  # noqa: E402

xy = np.array([[20.0, 15.0], [40.0, 30.0], [60.0, 45.0]])
flat = sm.Tool("flat", 5.0)
z_mesh, _ = drop_cutter(solid, flat, xy, tolerance=0.01)
z_exact, contact = drop_cutter(solid, flat, xy, tolerance=0.01, exact=True)
print("flat end mill tip heights, exact:", z_exact.round(6),
      "mesh (lifted by its deflection) - exact:", (z_mesh - z_exact).round(6))
