"""``surfmod toolpath FILE.step --tool ball --radius R --scallop h --out path.nc``."""

from __future__ import annotations

from ..errors import SurfmodError


def register(sub) -> None:
    p = sub.add_parser("toolpath", help="drop-cutter zig-zag finishing path over a STEP part, written as G-code")
    p.add_argument("path", help="STEP file")
    p.add_argument("--tool", default="ball", choices=("ball", "flat"))
    p.add_argument("--radius", type=float, required=True, help="tool radius (mm)")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--scallop", type=float, help="scallop (cusp) height for a ball cutter")
    g.add_argument("--stepover", type=float, help="distance between passes")
    p.add_argument("--step", type=float, help="spacing of points along a pass (default radius/4)")
    p.add_argument("--direction", default="x", choices=("x", "y"))
    p.add_argument("--feed", type=float, default=600.0, help="feed rate mm/min")
    p.add_argument("--safe-height", type=float, help="rapid-move height (default 5 mm above the part)")
    p.add_argument("--out", required=True, help="output .nc/.gcode/.ngc")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    from tqdm import tqdm

    from ..atomic import target_path
    from ..io.gcode import export_gcode
    from ..uses.inputs import to_shape
    from ..uses.toolpath import Tool, toolpath

    target_path(args.out, "out", (".nc", ".gcode", ".ngc", ".tap", ".cnc"))
    if args.radius is None or not args.radius > 0:
        raise SurfmodError(f"radius: tool radius must be > 0, got {args.radius}")
    with tqdm(total=3, desc="toolpath", unit="step", disable=args.no_progress) as bar:
        shape = to_shape(args.path, "path")
        bar.update()
        tp = toolpath(shape, Tool(args.tool, args.radius), args.stepover, scallop=args.scallop,
                      step=args.step, direction=args.direction, progress=not args.no_progress)
        bar.update()
        export_gcode(tp, args.out, feed=args.feed, safe_height=args.safe_height)
        bar.update()
    print(tp)
    print(f"wrote {args.out}")
    return 0
