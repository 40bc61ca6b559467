"""Rest machining: a smaller ball cuts only what the finishing ball could not reach.

A block with a pocket whose inner edges are rounded by 1 mm is roughed with a flat end
mill and finished with a ball of radius 2: the ball cannot follow the 1 mm fillets, so
a band of material stays along the pocket's floor edges and in its corners.
``sm.Rest(tool)`` sweeps the job's own stock model along the moves already made, finds
where more than the scallop is left, and cuts there (and only there) with a ball of
radius 0.75; its report gives the area left before and after.  The program has three
tool changes and is verified against the exact part like every job.
"""

from pathlib import Path

import build123d as bd

import surfmod as sm

HERE = Path(__file__).resolve().parent.parent
OUT = HERE / "step_samples"
OUT.mkdir(exist_ok=True)

# the part: a 30 x 30 x 8 block with a 14 x 14 x 3 pocket, every inner edge rounded by 1 mm
block = bd.Box(30, 30, 8) - bd.Pos(0, 0, 2.5) * bd.Box(14, 14, 3)
inner = [e for e in block.edges() if e.center().Z < 4 - 1e-6 and max(abs(e.center().X), abs(e.center().Y)) < 7.01]
part = block.fillet(1.0, inner)
bd.export_step(part, str(OUT / "cam_rest_part.step"))

job = sm.machine(part, 1.0, [
    sm.Rough(sm.Tool("flat", 2.0), stepdown=1.5, allowance=0.3),
    sm.Finish(sm.Tool("ball", 2.0), scallop=0.05),
    sm.Rest(sm.Tool("ball", 0.75)),  # after every operation before it; the finishing's scallop
])
print(job)
rest = job.operations[2].report
print(f"area left thicker than {rest['threshold']:.3g} mm: {rest['before']['area']:.4g} mm^2 after finishing, "
      f"{rest['left']['area']:.4g} mm^2 after the rest tool")
print(f"verified: {job.verification.ok}")
sm.export_gcode(job, OUT / "cam_rest_job.ngc", post="linuxcnc")
text = (OUT / "cam_rest_job.ngc").read_text().splitlines()
print(f"cam_rest_job.ngc: {len(text)} lines, {sum(ln.endswith('M6') for ln in text)} tool changes")
