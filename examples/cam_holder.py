"""Holder and shank: a deep pocket that needs a longer tool.

A 24 x 24 x 10 block has a 12 x 12 pocket 8 deep.  The tools sit in a holder of radius 7,
wider than the pocket: with 4 mm flutes and no shank sticking out, the holder would stand
on the block before the tool reaches the floor, so the moves below that are left out and
the floor left uncut is reported (area, deepest point).  With 10 mm flutes and 1 mm of
shank the same pocket is cut to its floor, and a rest ball then cuts into the corners the
finishing ball could not reach.  Both programs are verified against the exact part, the
holder's clearance included; ``strict=True`` would refuse the first job instead.
"""

from pathlib import Path

import build123d as bd

import surfmod as sm

HERE = Path(__file__).resolve().parent.parent
OUT = HERE / "step_samples"
OUT.mkdir(exist_ok=True)

part = bd.Box(24, 24, 10) - bd.Pos(0, 0, 1) * bd.Box(12, 12, 8)  # top z = 5, pocket floor z = -3


def tools(flute, shank):
    """A flat, a ball and a small ball in the same holder (radius 7, 20 long)."""
    holder = dict(flute_length=flute, shank_length=shank, holder_radius=7.0, holder_length=20.0)
    return sm.Tool("flat", 2.0, **holder), sm.Tool("ball", 1.5, **holder), sm.Tool("ball", 0.75, **holder)


rough, finish, _ = tools(4.0, 0.0)
short = sm.machine(part, 0.0, [sm.Rough(rough, stepdown=2.0, allowance=0.3), sm.Finish(finish, scallop=0.05)])
print(short)
for op in short.operations:
    held = op.report["holder"]
    print(f"short tool, {op.name}: floor left {held.area:.4g} mm^2, deepest z {held.deepest[2]:.4g}")
print(f"short tool verified: {short.verification.ok}")

rough, finish, small = tools(10.0, 1.0)
long = sm.machine(part, 0.0, [sm.Rough(rough, stepdown=2.0, allowance=0.3), sm.Finish(finish, scallop=0.05),
                              sm.Rest(small)])
print(long)
inside = [op.moves[(abs(op.moves[:, 0]) < 6) & (abs(op.moves[:, 1]) < 6)] for op in long.operations]
lowest = min(float(p[:, 2].min()) for p in inside if len(p))
print(f"long tool: nothing held back: {all(op.report['holder'] is None for op in long.operations)}, "
      f"lowest cut in the pocket z {lowest:.4g}")
print(f"long tool verified: {long.verification.ok}")
sm.export_gcode(long, OUT / "cam_holder_job.ngc", post="linuxcnc")
