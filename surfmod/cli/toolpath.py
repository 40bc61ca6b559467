"""``surfmod toolpath FILE.step --tool ball --radius R --scallop h --out path.nc``.

The same concept as :mod:`surfmod.cam.toolpath`, one level up: the command over it.
"""

from __future__ import annotations

import sys

from ..atomic import target_path
from ..errors import SurfmodError
from ..cam.gcode import export_gcode
from ..cam.post import SUFFIXES
from ..inputs import to_shape
from ..cam.toolpath import Tool, toolpath
from ..cam.verify import verify_toolpath
from . import EXIT_PARTIAL

def register(sub) -> None:
    p = sub.add_parser("toolpath", help="drop-cutter zig-zag finishing path over a STEP part, every move "
                                        "gouge-checked, written as G-code")
    p.add_argument("path", help="STEP file")
    p.add_argument("--tool", default="ball", choices=("ball", "flat"))
    p.add_argument("--radius", type=float, required=True, help="tool radius (mm)")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--scallop", type=float, help="scallop (cusp) height for a ball cutter")
    g.add_argument("--stepover", type=float, help="distance between passes")
    p.add_argument("--step", type=float, help="spacing of points along a pass (default radius/4)")
    p.add_argument("--tolerance", type=float,
                   help="depth no move may cut (default scallop/10, or radius/100 without a scallop)")
    p.add_argument("--direction", default="x", choices=("x", "y"))
    p.add_argument("--feed", type=float, default=600.0, help="feed rate mm/min")
    p.add_argument("--safe-height", type=float, help="rapid-move height (default 5 mm above the part)")
    p.add_argument("--out", required=True, help="output .nc/.gcode/.ngc")
    p.add_argument("--no-verify", action="store_true",
                   help="skip judging the written G-code against the exact faces (faster)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    """Build the path, judge its G-code against the exact faces
    (:func:`~surfmod.cam.verify.verify_toolpath`, unless ``--no-verify``) and write it.
    When no path keeps every move within the tolerance (``NoSafePathError``, a
    ``SurfmodError``) the common handler prints one line naming the file and exits 1; no
    file is written.  Exit 3: written, but the exact faces come deeper into the tool than
    the tolerance somewhere (the lines before say where)."""
    target_path(args.out, "out", SUFFIXES)
    if args.radius is None or not args.radius > 0:
        raise SurfmodError(f"radius: tool radius must be > 0, got {args.radius}")
    shape = to_shape(args.path, "path")
    path = toolpath(shape, Tool(args.tool, args.radius), args.stepover, scallop=args.scallop, step=args.step,
                    direction=args.direction, tolerance=args.tolerance, progress=not args.no_progress)
    text = path.to_gcode(feed=args.feed, safe_height=args.safe_height)
    verdict = None if args.no_verify else verify_toolpath(path, shape, text=text)
    export_gcode(path, args.out, feed=args.feed, safe_height=args.safe_height)
    print(path)
    if verdict is not None:
        for line in verdict.lines():
            print(line)
    print(f"wrote {args.out}")
    if verdict is not None and not verdict.ok:
        print("the path cuts the exact part deeper than its tolerance: written, exit 3", file=sys.stderr)
        return EXIT_PARTIAL
    return 0
