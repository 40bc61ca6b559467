"""``surfmod gallery OUTDIR``: build every entity, cross-check, write STEP/STL/PNG, print a table."""

from __future__ import annotations

from ..gallery.runner import format_table, run_gallery


def register(sub) -> None:
    p = sub.add_parser("gallery", help="build every lecture entity, cross-check it, export STEP/STL/PNG")
    p.add_argument("outdir", help="output folder (created if missing)")
    p.add_argument("--only", nargs="+", metavar="NAME", help="build only these entities (file stems)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    rows = run_gallery(args.outdir, progress=not args.no_progress, only=args.only)
    print(format_table(rows))
    failed = [r.name for r in rows if not r.passed]
    print(f"\n{len(rows) - len(failed)} of {len(rows)} entities passed" + (f"; failed: {', '.join(failed)}" if failed else ""))
    return 1 if failed else 0
