"""Machining from stock: a STEP part roughed with a flat end mill and finished with a ball.

``sm.machine`` takes the part and a block of stock (its box grown by a margin) to a job:
z-level roughing down to the part plus an allowance, then the gouge-checked drop-cutter
finishing.  The LinuxCNC program has tool changes, length offsets, spindle starts and
arcs (``G2``/``G3``) where the path is circular; ``surfmod machine`` is the same from the
command line.  A second job machines a pocketed part of the test corpus.
"""

from pathlib import Path

import surfmod as sm
from surfmod.cam.picture import write_png

HERE = Path(__file__).resolve().parent.parent
OUT = HERE / "step_samples"
OUT.mkdir(exist_ok=True)

# 1. the NURBS mould of examples/cam_toolpath.py (80 x 60 mm), from 2 mm of stock all round
#    and on top: a 10 mm flat end mill leaving 0.5 mm, then a 6 mm ball leaving 0.15 mm cusps
part = OUT / "cam_part.step"
if not part.exists():  # a copy of examples/ alone: the same mould, built here
    import numpy as np

    n, p = 7, 3
    k = np.concatenate([[0] * p, np.linspace(0, 1, n - p + 1), [1] * p])
    g = np.array([k[i + 1:i + p + 1].mean() for i in range(n)])
    z = 20 + 6 * np.sin(np.pi * g[:, None]) * np.sin(np.pi * g[None, :]) - 3 * np.cos(3 * g[:, None])
    net = np.stack(np.broadcast_arrays(80 * g[:, None], 60 * g[None, :], z), -1)
    w = np.ones((n, n))
    w[3, 3] = 2.0
    bot = net.copy()
    bot[..., 2] = 0
    sides = [sm.BSplineSurface(np.stack([a, b]), (1, p), ([0, 0, 1, 1], k), np.stack([wa, wa]))
             for a, b, wa in [(net[0], bot[0], w[0]), (net[-1], bot[-1], w[-1]),
                              (net[:, 0], bot[:, 0], w[:, 0]), (net[:, -1], bot[:, -1], w[:, -1])]]
    part = sm.make_solid([sm.BSplineSurface(net, (p, p), (k, k), w), sm.plane((0, 0, 0), (80, 0, 0), (0, 60, 0)),
                          *sides])
rough = sm.Rough(sm.Tool("flat", 5.0), stepdown=5.0, allowance=0.5)
finish = sm.Finish(sm.Tool("ball", 3.0), scallop=0.15)
job = sm.machine(str(part) if isinstance(part, Path) else part, 2.0, [rough, finish])
print(job)
sm.export_gcode(job, OUT / "cam_job.ngc", post="linuxcnc")
write_png(job, OUT / "cam_job.png")
fin = job.operations[1].report
print(f"finishing: stepover {fin['stepover']:.4g}, max gouge {fin['gouge']:.2e} (tolerance {fin['tolerance']:.2e})")
text = (OUT / "cam_job.ngc").read_text().splitlines()
print(f"cam_job.ngc: {len(text)} lines, {sum(ln.startswith('T') for ln in text)} tool changes")

# 2. a pocketed part of the corpus (stepcode TAIL_MIDDLE_PART, 45 x 90 x 36 mm) with a
#    bull-nose finisher: its helix entry is written as G3 arcs
corpus = HERE / "tests" / "data" / "step" / "stepcode_TAIL_MIDDLE_PART.stp"
if corpus.exists():
    job2 = sm.machine(str(corpus), 2.0, [sm.Rough(sm.Tool("flat", 5.0, flute_length=45), allowance=0.5),
                                         sm.Finish(sm.Tool("bull", 3.0, 1.0, flute_length=45), stepover=2.5)])
    print(job2)
    fin = job2.operations[1].report
    print(f"finishing: max gouge {fin['gouge']:.2e} (tolerance {fin['tolerance']:.2e})")
    # a stepover, not a scallop: on the walls the contours 2.5 apart leave the cusps of the
    # bull's corner (Cutter.wall_cusp), which the verdict holds them to
    print(f"pocket job verified: {job2.verification.ok}")
    paths = sm.export_gcode(job2, OUT / "cam_job_pocket.nc", post="grbl")
    arcs = sum(ln.startswith(("G2 ", "G3 ")) for p in paths for ln in p.read_text().splitlines())
    print(f"GRBL programs {[p.name for p in paths]}, {arcs} arc words")
    for p in paths:  # the picture and the first job's program are the samples kept
        p.unlink()
