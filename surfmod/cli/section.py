"""``surfmod section FILE.step --origin x y z --normal x y z --out file.dxf``.

The same concept as :mod:`surfmod.uses.section`, one level up: the command over it.  A
part OCCT cannot section whole is sectioned face by face: the faces it cannot intersect
are named, the others' curves written, and the command exits 3 (partial).
"""

from __future__ import annotations

from pathlib import Path

from ..errors import SurfmodError
from ..io.svg import export_svg
from ..inputs import to_shape
from ..uses.section import section
from . import EXIT_PARTIAL
from tqdm import tqdm


def register(sub) -> None:
    p = sub.add_parser("section", help="planar section of a STEP part to DXF / SVG (+ PNG preview)")
    p.add_argument("path", help="STEP file")
    p.add_argument("--origin", nargs=3, type=float, required=True, metavar=("X", "Y", "Z"))
    p.add_argument("--normal", nargs=3, type=float, required=True, metavar=("X", "Y", "Z"))
    p.add_argument("--out", required=True, help="output .dxf or .svg")
    p.add_argument("--png", help="also write a PNG preview")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    from ..io.dxf import export_dxf

    suffix = Path(args.out).suffix.lower()
    if suffix not in (".dxf", ".svg"):
        raise SurfmodError(f"out: expected a .dxf or .svg file, got {args.out}")
    with tqdm(total=3, desc="section", unit="step", disable=args.no_progress) as bar:
        shape = to_shape(args.path, "path")
        bar.update()
        s = section(shape, args.origin, args.normal, partial=True)
        bar.update()
        if s.empty and s.faces_skipped:
            raise SurfmodError(f"obj: the plane crosses no face but {sorted(s.faces_skipped)}, which OCCT could not "
                               "intersect: nothing to write")
        if s.empty:  # bad input like any other: one line on stderr, exit 1, no file
            raise SurfmodError(f"origin: the plane through {tuple(args.origin)} with normal {tuple(args.normal)} "
                               "misses the part: the section is empty")
        (export_dxf if suffix == ".dxf" else export_svg)(s, args.out)
        if args.png:
            s.preview(args.png)
        bar.update()
    print(s)
    wrote = f"wrote {args.out}" + (f" and {args.png}" if args.png else "")
    if s.faces_skipped:
        from ..occ.topo import faces_of

        for i, reason in sorted(s.faces_skipped.items()):
            print(f"face {i} skipped: {reason}")
        print(f"partial: {len(s.faces_skipped)} of {len(faces_of(shape))} face(s) skipped (OCCT could not intersect "
              f"them); {wrote} with the curves of the others")
        return EXIT_PARTIAL
    print(wrote)
    return 0
