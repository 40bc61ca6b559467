"""A machining job in the OCP CAD Viewer, where build123d users look at their parts.

``sm.to_build123d(job)`` hands the viewer one compound: the part, the stock's edges, and per
operation its cutting moves (one colour each) and its rapids (red), as a tree one can
switch on and off.  Surfaces, meshes, tool paths and analysis results go the same way.
With the optional viewer extra (``pip install "surfmod[viewer]"``) and the VS Code
extension running, ``python examples/cam_job_viewer.py --show`` draws it there.
"""

import sys
from pathlib import Path

import build123d as bd
import numpy as np

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)

# a 60 x 40 x 15 mm block with a round pocket and a chamfered rim, built in build123d
with bd.BuildPart() as block:
    bd.Box(60, 40, 15)
    with bd.Locations((0, 0, 7.5)):
        bd.Cylinder(12, 8, mode=bd.Mode.SUBTRACT)
    bd.chamfer(block.edges().group_by(bd.Axis.Z)[-1].filter_by(bd.GeomType.LINE), 2.0)

job = sm.machine(block.part, 2.0, [sm.Rough(sm.Tool("flat", 4.0), stepdown=4.0, allowance=0.4),
                                   sm.Finish(sm.Tool("ball", 2.5), scallop=0.1)])
print(job)
sm.export_step(block.part, OUT / "cam_job_viewer_part.step")
sm.export_gcode(job, OUT / "cam_job_viewer.ngc", post="linuxcnc")

view = sm.to_build123d(job)
for node in view.children:
    kinds = ", ".join(f"{child.label}: {len(child.edges())} moves" for child in node.children
                      if child.label.endswith(("cuts", "rapids")))
    print(f"{node.label:<22} {kinds or f'{len(node.faces())} faces, {len(node.edges())} edges'}")
# every move of the program is an edge of the view (moves shorter than OCCT's 1e-7 aside)
made = sum(int((np.linalg.norm(np.diff(op.moves, axis=0), axis=1) > 1e-7).sum()) for op in job.operations)
print(f"moves shown {sum(len(node.edges()) for node in view.children[2:])} of {made}")

if "--show" in sys.argv:
    from ocp_vscode import show  # the optional extra 'viewer'

    show(view)
