"""Machining from stock: the CAM part roughed from a block and finished, one LinuxCNC program.

The part (``cam_part.step``, the NURBS mould of ``cam_toolpath.py``) sits in a block of stock
grown 3 mm round it and on top.  Tool 1, a 6 mm flat end mill, clears the block in z-levels
2 mm apart down to the part plus 0.5 mm (contour-parallel rings, ramp entries, links above
the stock); tool 2, a 6 mm ball, finishes with a 0.05 mm scallop, every move checked
against the part.  The program has the tool changes, length offsets and spindle starts a
controller needs (LinuxCNC's ``rs274`` reads it back in the tests).
"""

from pathlib import Path

import surfmod as sm

OUT = Path(__file__).resolve().parent.parent / "step_samples"
OUT.mkdir(exist_ok=True)
part = OUT / "cam_part.step"
if not part.exists():  # written by cam_toolpath.py
    import runpy

    runpy.run_path(str(Path(__file__).with_name("cam_toolpath.py")))

job = sm.machine(str(part), 3.0, [sm.Rough(sm.Tool("flat", 3.0), stepdown=2.0, allowance=0.5),
                                  sm.Finish(sm.Tool("ball", 3.0), scallop=0.05)])
print(job)
written = sm.export_gcode(job, OUT / "cam_job.ngc", post="linuxcnc")
text = written[0].read_text()
print("program:", [ln for ln in text.splitlines() if ln.startswith(("T", "G43", "S", "M"))])
(OUT / "cam_job.png").write_bytes(job._repr_png_())
print("wrote", written[0].name, "and cam_job.png")
