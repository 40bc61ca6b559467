"""Cycle time a machine keeps against the plain feed-rate sum, on a real job.

Not a timing of surfmod: the job of examples/cam_machining.py (``sm.machine`` on
``step_samples/cam_part.step`` from 2 mm of stock, roughing with a flat r = 5, stepdown 5,
allowance 0.5; finishing with a ball r = 3) at two finishing scallops, its moves planned by
:mod:`surfmod.cam.cycle_time` on machines with different limits, beside
``Operation.feed_time`` (every move at its feed from end to end).

* where the time goes, per operation and kind of move on the default machine
  (:data:`surfmod.cam.machine_table.MACHINE`): the feed-rate sum, the estimate, what the
  axis velocity limits add (a move held below its feed by its slowest axis: ``L/v_axis -
  L/feed``) and what accelerating, braking and the corners add (the rest), and the share
  of moves too short to reach their speed (a triangular profile);
* the whole job on several machines, at the tools' own feeds and at a router's feed
  (``ROUTER``): the ratio of estimate to feed-rate sum.

``python -m benchmarks cycletime``
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

import surfmod as sm
from surfmod.cam.cycle_time import SHORTEST, cycle_time, feed_time, plan, rates
from surfmod.cam.machine_table import MACHINE
from surfmod.cam.roughing import FEED, PLUNGE, RAPID

from .tables import Table, heading, note

JOB_PART = Path(__file__).resolve().parent.parent / "step_samples" / "cam_part.step"
SCALLOPS = (0.15, 0.05)
#: A router's feed in wood or plastic (mm/min): where acceleration and corners dominate.
ROUTER = 4000.0
KINDS = ((RAPID, "rapid"), (FEED, "cut"), (PLUNGE, "ramp/plunge"))
MACHINES = (
    ("hobby mill (the default)", MACHINE),
    ("hobby mill, exact stop (P = 0)", replace(MACHINE, blend_tolerance=0.0)),
    ("hobby mill, P = 0.05", replace(MACHINE, blend_tolerance=0.05)),
    ("slow to accelerate (100 mm/s²)", sm.Machine(max_acceleration=100.0)),
    ("stiff mill (10000 mm/min, 2000 mm/s²)", sm.Machine(max_velocity=10000.0, max_acceleration=2000.0,
                                                           rapid=10000.0)),
)


def job(scallop: float):
    return sm.machine(str(JOB_PART), 2.0, [sm.Rough(sm.Tool("flat", 5.0), stepdown=5.0, allowance=0.5),
                                           sm.Finish(sm.Tool("ball", 3.0), scallop=scallop)])


def _seconds(s: float) -> str:
    return f"{s:.0f}" if s >= 100 else f"{s:.1f}"


def _tools(j, feed: float | None):
    """The operations of ``j`` with their tools, or with the tools at ``feed`` (plunge a third)."""
    return [(op, op.tool if feed is None else replace(op.tool, feed=feed, plunge_feed=feed / 3))
            for op in j.operations]


def where_rows(j, scallop: float, feed: float | None):
    """Rows of where the time goes, per operation and move kind, on the default machine."""
    for op, tool in _tools(j, feed):
        feeds = rates(op.motion, tool, MACHINE)
        kind = op.motion.kind[1:]
        seg = np.linalg.norm(np.diff(op.motion.points, axis=0), axis=1)
        has = seg > SHORTEST  # the moves the plan keeps
        p = plan(op.motion.points, feeds, MACHINE)
        kinds, commanded = kind[has], feeds[has] / 60.0
        for code, label in KINDS:
            sel = kinds == code
            if not sel.any():
                continue
            length = p.length[sel]
            plain = float((length / commanded[sel]).sum())
            axes = float((length / p.cruise[sel]).sum()) - plain
            total = float(p.time[sel].sum())
            short = float(np.mean(p.peak[sel] < p.cruise[sel] * (1 - 1e-9)))
            yield (f"{op.name} (scallop {scallop:g})" if op.name == "finishing" else op.name,
                   "the tool's" if feed is None else f"{feed:g}", label,
                   str(int(sel.sum())), f"{np.median(length):.3g}", _seconds(plain), _seconds(total),
                   f"{total / plain:.2f}", _seconds(axes), _seconds(total - plain - axes), f"{100 * short:.0f}%")


def main() -> None:
    jobs = {s: job(s) for s in SCALLOPS}
    heading(f"where the time goes: step_samples/cam_part.step, {MACHINE}")
    table = Table(("operation", 28, "<"), ("feed", 10, "<"), ("moves", 12, "<"), ("count", 7), ("median mm", 9), ("feed sum s", 10),
                  ("estimate s", 10), ("ratio", 6), ("axes s", 7), ("accel+corners s", 15), ("triangular", 10))
    table.header()
    for feed in (None, ROUTER):
        for row in where_rows(jobs[SCALLOPS[-1]], SCALLOPS[-1], feed):
            table.row(*row)
    note("feed sum: length over the commanded rate (G0 at the rapid rate); estimate: the trapezoidal profile with "
         "corner blending (surfmod.cam.cycle_time); axes: what the per-axis velocity limits add (Z rapids at "
         "3000 mm/min instead of 5000); accel+corners: the rest; triangular: moves too short to reach their speed. "
         f"Feed: the tool's own (the last note gives them) or a router's {ROUTER:g} mm/min. Tool changes (8 s each) are left out.")
    heading("the whole job on several machines, at the tools' own feeds and at a router's (tool changes included)")
    table = Table(("machine", 38, "<"), ("feeds", 22, "<"),
                  *(c for s in SCALLOPS for c in ((f"{s:g}: feed sum s", 15), (f"{s:g}: estimate s", 15),
                                                  (f"{s:g}: ratio", 9))))
    table.header()
    for label, machine in MACHINES:
        for feeds, feed in (("the tools' own", None), (f"{ROUTER:g} mm/min", ROUTER)):
            cells = []
            for s in SCALLOPS:
                ops = _tools(jobs[s], feed)
                plain = sum(feed_time(op.motion, tool, machine) + machine.tool_change for op, tool in ops)
                est = sum(cycle_time(op.motion, tool, machine) + machine.tool_change for op, tool in ops)
                cells += [_seconds(plain), _seconds(est), f"{est / plain:.2f}"]
            table.row(label, feeds, *cells)
    tools = ", ".join(f"{op.tool}: feed {op.tool.feed:g}, plunge {op.tool.plunge_feed:g}"
                      for op in jobs[SCALLOPS[0]].operations)
    note(f"the tools' own feeds are their defaults ({tools} mm/min); the router's feed is the same moves at "
         f"{ROUTER:g} mm/min (plunge a third).  The feed sum takes each machine's rapid rate.")

if __name__ == "__main__":
    main()
