"""``surfmod conformance --evaluator NAME|MODULE:FUNCTION``: hold an evaluator against OCCT
and the 40-digit reference (:func:`surfmod.conformance`); one row per case and order."""

from __future__ import annotations

from ..conform import conformance
from .batch import RowSink

COLUMNS = [("case", "<44.44"), ("order", ">5d"), ("evaluator", ">10.1e"), ("OCCT", ">10.1e"), ("right", "<9.9"),
           ("conforms", "<8.8")]


def register(sub) -> None:
    p = sub.add_parser("conformance", help="hold an evaluator of B-spline/NURBS surfaces and curves against OCCT "
                                           "and a 40-digit reference")
    p.add_argument("--evaluator", required=True, metavar="NAME|MODULE:FUNCTION",
                   help="surfmod, surfmod-patches, surfmod-numpy, occt, geomdl, splipy, rhino3dm, or MODULE:FUNCTION, a function "
                        "f(surface, u, v, order) returning partials (N, order+1, order+1, 3) "
                        "(f(surface, u, v) returning positions with --orders 0)")
    p.add_argument("--cases", default="stress", metavar="stress|lecture|corpus|PATH.step",
                   help="the cases: the stress family (default), the lecture's entities, the real-parts corpus "
                        "or the B-spline faces of a STEP file")
    p.add_argument("--orders", type=int, default=2, help="highest derivative order held, 0 to 2 (default 2)")
    p.add_argument("--csv", help="write the rows to this CSV file instead of printing the table")
    p.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    table = conformance(args.evaluator, args.cases, args.orders, progress=not args.no_progress)
    if args.markdown:
        print(table.markdown(), end="")
    else:
        sink = RowSink(COLUMNS, args.csv)
        for r in table.rows:
            sink.add((r.case, r.order, r.error, r.occt_error, r.right, "yes" if r.ok else "NO"))
        sink.close()
        print(table.summary() + (f"; rows in {args.csv}" if args.csv else ""))
    return 0 if table.passed else 1
