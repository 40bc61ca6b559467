"""``surfmod machine PART.step --out JOB.ngc --stock-margin M --rough flat:R --finish ball:R --scallop S
[--rest ball:r] [--strict]``."""

from __future__ import annotations

import sys
from dataclasses import replace

from ..atomic import target_path
from ..cam.finishing import summary_lines
from ..cam.job import Finish, Rest, Rough, machine
from ..cam.machine_table import MACHINE, load_machine_table
from ..cam.post import POSTS, SUFFIXES, export_job, program_paths, programs
from ..cam.tool import load_tool_table, parse_tool
from ..cam.verify import verify_job
from ..errors import SurfmodError
from ..inputs import to_shape
from . import EXIT_PARTIAL


def register(sub) -> None:
    p = sub.add_parser("machine", help="machine a STEP part from stock: z-level roughing, drop-cutter and "
                                       "waterline finishing, a LinuxCNC or GRBL program")
    p.add_argument("path", help="STEP file (the part, a solid)")
    p.add_argument("--out", required=True, help="output program .ngc/.nc (GRBL: one file per tool, NAME_T<n>)")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--stock-margin", type=float, help="stock = part box grown by M on the sides and on top (mm)")
    g.add_argument("--stock", type=float, nargs=6, metavar=("X0", "Y0", "Z0", "X1", "Y1", "Z1"),
                   help="stock box in part coordinates")
    p.add_argument("--rough", required=True, help="roughing tool flat:R, ball:R or bull:R:r (tool 1)")
    p.add_argument("--finish", required=True, help="finishing tool flat:R, ball:R or bull:R:r (tool 2)")
    finishing = p.add_mutually_exclusive_group(required=True)
    finishing.add_argument("--scallop", type=float, help="finishing scallop height (mm)")
    finishing.add_argument("--stepover", type=float,
                           help="finishing passes and contours this far apart instead (mm; a flat end mill)")
    p.add_argument("--rest", help="rest machining tool flat:R, ball:R or bull:R:r (tool 3): cuts only where the "
                                  "finishing left more than the scallop (a tool no smaller than the finishing's: "
                                  "a warning)")
    p.add_argument("--stepdown", type=float, help="roughing level spacing (default the rough tool radius)")
    p.add_argument("--allowance", type=float, default=0.5, help="material roughing leaves on the part (mm)")
    p.add_argument("--post", default="linuxcnc", help=f"post-processor: {', '.join(POSTS)}")
    p.add_argument("--tools", help="tool table (TOML or JSON) giving tools 1, 2 (and 3) their flutes, speeds, feeds")
    p.add_argument("--png", help="picture of the moves over the shaded part")
    p.add_argument("--machine", help="machine table (TOML [machine] or JSON): axis velocities and accelerations, "
                                     "rapid rate, blend tolerance, tool change time of the time estimate")
    p.add_argument("--html", help="the job in the browser: part, moves per operation, stock left (one file, "
                                  "no network needed)")
    p.add_argument("--no-verify", action="store_true",
                   help="skip reading the program back and judging it against the exact part and the stock "
                        "(faster; the program's header says it was not verified)")
    p.add_argument("--strict", action="store_true",
                   help="refuse (exit 1, nothing written) where a tool's shank or holder would collide, instead "
                        "of leaving that region uncut and reporting it")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def _tool(text: str, number: int, table: dict, name: str):
    tool = parse_tool(text, name)
    entry = table.get(number)
    if entry is None:
        return tool
    if (entry.kind, entry.radius, entry.corner_radius) != (tool.kind, tool.radius, tool.corner_radius):
        raise SurfmodError(f"{name}: {text} is not tool {number} of the tool table ({entry})")
    return entry


def run(args) -> int:
    """Check every argument before any work, machine (the job's program judged and, where
    the scallop is broken, re-cut: :func:`~surfmod.cam.job.machine`; GRBL's programs judged
    as written), write them with the verdict in their header and print the summary.  Exit 0 when every promise holds, 3 when the program
    is written but a promise is broken (the lines before say which and where); on bad
    input one line and exit 1, nothing written.  Where a shank or holder would collide the
    region is left and reported (exit 0 when every promise holds); ``--strict`` refuses
    instead: one line, exit 1, nothing written (the input asks what the tools cannot do)."""
    if args.post not in POSTS:
        raise SurfmodError(f"post: expected one of {', '.join(POSTS)}, got {args.post!r}")
    target_path(args.out, "out", SUFFIXES)
    if args.png:
        target_path(args.png, "png", (".png",))
    if args.html:
        target_path(args.html, "html", (".html", ".htm"))
    table = load_tool_table(args.tools) if args.tools else {}
    mill = load_machine_table(args.machine) if args.machine else MACHINE
    rough_tool = _tool(args.rough, 1, table, "rough")
    finish_tool = _tool(args.finish, 2, table, "finish")
    rest_tool = _tool(args.rest, 3, table, "rest") if args.rest else None
    if args.stepdown is not None and not args.stepdown > 0:
        raise SurfmodError(f"stepdown: must be > 0, got {args.stepdown:g}")
    # the finishing's scallop is checked against its tool by sm.machine before any work
    if rest_tool is not None and args.scallop is not None and args.scallop >= rest_tool.radius:
        raise SurfmodError(f"scallop: {args.scallop:g} must be smaller than the rest tool radius {rest_tool.radius:g}")
    if not args.allowance >= 0:
        raise SurfmodError(f"allowance: must be >= 0, got {args.allowance:g}")
    if args.stock_margin is not None and not args.stock_margin >= 0:
        raise SurfmodError(f"stock_margin: must be >= 0, got {args.stock_margin:g}")
    shape = to_shape(args.path, "path", solid=True)
    stock = args.stock_margin if args.stock is None else [args.stock[:3], args.stock[3:]]
    ops = [Rough(rough_tool, stepdown=args.stepdown, allowance=args.allowance),
           Finish(finish_tool, scallop=args.scallop, stepover=args.stepover)] + ([Rest(rest_tool)] if rest_tool is not None else [])
    job = machine(shape, stock, ops, progress=not args.no_progress, verify=not args.no_verify,
                  machine=mill, strict=args.strict)
    texts = programs(job, args.post)  # any refusal before a file is written
    program_paths(args.out, job, args.post)
    if args.no_verify:
        note = "not verified: --no-verify, no check against the exact part or the stock"
    else:
        if args.post != "linuxcnc":  # the program as this post writes it, read back and judged
            job = replace(job, verification=verify_job(job, args.post, texts))
        note = ("verified: " if job.verification.ok else "VERIFICATION FAILED: ") + "; ".join(
            str(f) for f in job.verification.findings)
    written = export_job(job, args.out, args.post, note=note)
    if args.png:
        from ..cam.picture import write_png

        write_png(job, args.png)
    if args.html:
        from ..cam.job_view import write_html

        write_html(job, args.html)
    print(job)
    if args.machine:  # the limits the time estimates below follow
        print(f"  {job.machine}")
    for op in job.operations:
        print(f"  {op.name}: length {op.length:.1f} mm, time estimate {op.time_estimate:.1f} s "
              f"(feed-rate sum {op.feed_time:.1f} s), tool {op.tool}")
        if op.name == "finishing":
            for line in summary_lines(op.report):
                print(f"    {line}")
    for p in written + [path for path in (args.png, args.html) if path]:
        print(f"wrote {p}")
    if job.verification is not None and not job.verification.ok:
        broken = [f.what for f in job.verification.findings if not f.ok]
        print(f"the program breaks a promise ({', '.join(broken)}): written, exit 3", file=sys.stderr)
        return EXIT_PARTIAL
    return 0
