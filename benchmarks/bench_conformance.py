"""Evaluator conformance: every shipped adapter held against OCCT and the 40-digit reference.

For the stress family and the lecture's entities, each case and derivative order gets one
row (for the B-spline faces of the corpus, only the rows where some adapter fails) with
the worst relative error of OCCT and of every adapter — surfmod's compiled basis kernel,
its per-span Taylor patches (used for many points on small nets of degree <= 3), its
NumPy path, geomdl, splipy, rhino3dm — all from ``sm.conformance``, the function
``surfmod conformance --evaluator NAME --cases SET`` runs, in one process.  An error in
bold is worse than ``max(OCCT's, 1e-12)`` on that row; "—" is an order the library does
not evaluate (rhino3dm's surfaces give positions only), "absent" an adapter whose package
is not installed.  This is a precision table, not a timing: the machine does not matter.

``python -m benchmarks conformance``
"""

from __future__ import annotations

import surfmod as sm
from surfmod.conform import adapters

from .tables import Table, heading, note

NAMES = ["surfmod", "surfmod-patches", "surfmod-numpy", "geomdl", "splipy", "rhino3dm"]


def _cell(row) -> str:
    if row is None:
        return "—"
    return f"{row.error:.1e}" if row.ok else f"**{row.error:.1e}**"


def table_of(cases: str) -> None:
    tables = {n: None if adapters.missing(n) else sm.conformance(n, cases) for n in NAMES}
    heading(f"cases {cases!r}: worst relative error against the 40-digit reference")
    t = Table(("case", 44, "<"), ("order", 5), ("OCCT", 8), *[(n, 13) for n in NAMES])
    t.header()
    base = tables["surfmod-numpy"] or next(x for x in tables.values() if x)
    by = {n: {(r.case, r.order): r for r in x.rows} if x else None for n, x in tables.items()}
    for r in base.rows:
        cells = [_cell(by[n].get((r.case, r.order))) if by[n] is not None else "absent" for n in NAMES]
        t.row(r.case, str(r.order), f"{r.occt_error:.1e}", *cells)
    for n, x in tables.items():
        note(x.summary() if x else f"{n}: {adapters.missing(n)}")


def corpus() -> None:
    """The corpus's B-spline faces: only the rows where some adapter is worse than OCCT
    (468 faces, three orders each), then each adapter's count."""
    tables = {n: None if adapters.missing(n) else sm.conformance(n, "corpus") for n in NAMES}
    heading("cases 'corpus': the rows where some adapter is worse than OCCT")
    t = Table(("case", 44, "<"), ("order", 5), ("OCCT", 8), *[(n, 13) for n in NAMES])
    t.header()
    by = {n: {(r.case, r.order): r for r in x.rows} if x else None for n, x in tables.items()}
    base = tables["surfmod-numpy"] or next(x for x in tables.values() if x)
    for r in base.rows:
        mine = {n: by[n].get((r.case, r.order)) if by[n] is not None else None for n in NAMES}
        if any(x is not None and not x.ok for x in mine.values()):
            t.row(r.case, str(r.order), f"{r.occt_error:.1e}",
                  *[_cell(mine[n]) if by[n] is not None else "absent" for n in NAMES])
    for n, x in tables.items():
        note(x.summary().split(";")[0] if x else f"{n}: {adapters.missing(n)}")


def main() -> None:
    for cases in ("stress", "lecture"):
        table_of(cases)
    corpus()


if __name__ == "__main__":
    main()
