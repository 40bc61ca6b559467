"""``surfmod section FILE.step --origin x y z --normal x y z --out file.dxf``.

The same concept as :mod:`surfmod.uses.section`, one level up: the command over it.  A
part OCCT cannot section whole is sectioned face by face: the faces it cannot intersect
are named, the others' curves written, and the command exits 3 (partial).

Before it exits 0 the command judges the DXF it wrote: read back with ezdxf, its entities'
lengths computed exactly (lines and arcs in closed form, splines by Gauss-Legendre on the
NumPy evaluator over their own knot spans) must add up to the length of
``BRepAlgoAPI_Section``'s edges (``GCPnts_AbscissaPoint``) within ``LENGTH_RTOL``; else
it exits 3 saying by how much.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import SurfmodError
from ..nets.bspline import BSplineCurve
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


#: relative difference allowed between the DXF's length and OCCT's: both are exact to
#: ~1e-12 (OCCT's length at tolerance 1e-12, the splines' Gauss rule to round-off; on 14
#: corpus parts at two planes the worst difference was 1.1e-15), so this leaves room for
#: round-off over many entities, not for a lost, doubled or bent curve
LENGTH_RTOL = 1e-11
#: Gauss-Legendre nodes on each quarter of a spline's knot span
GAUSS_NODES = 24


def dxf_length(path) -> float:
    """Total length of the LINE, ARC, CIRCLE and SPLINE entities of a DXF file, computed
    from the entities as read back (ezdxf); another entity raises ``SurfmodError``.

    >>> import surfmod as sm, build123d as bd, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "s.dxf")
    >>> _ = sm.export_dxf(sm.section(bd.Box(2, 2, 2) - bd.Cylinder(0.5, 3), (0, 0, 0), (0, 0, 1)), path)
    >>> round(dxf_length(path), 12) == round(8 + 3.141592653589793, 12)
    True
    """
    import ezdxf

    x, w = np.polynomial.legendre.leggauss(GAUSS_NODES)
    total = 0.0
    for e in ezdxf.readfile(path).modelspace():
        kind = e.dxftype()
        if kind == "LINE":
            total += float(np.linalg.norm(np.subtract(e.dxf.end, e.dxf.start)))
        elif kind == "CIRCLE":
            total += 2 * math.pi * e.dxf.radius
        elif kind == "ARC":
            total += math.radians((e.dxf.end_angle - e.dxf.start_angle) % 360.0 or 360.0) * e.dxf.radius
        elif kind == "SPLINE":
            weights = np.array(e.weights) if len(e.weights) else None
            curve = BSplineCurve(np.array(e.control_points), e.dxf.degree, np.array(e.knots), weights)
            knots = np.unique(np.array(e.knots, dtype=float))
            cuts = np.unique(np.concatenate([np.linspace(a, b, 5) for a, b in zip(knots[:-1], knots[1:])]))
            a, b = cuts[:-1, None], cuts[1:, None]
            t = ((a + b) / 2 + (b - a) / 2 * x).ravel()
            speed = np.linalg.norm(curve.derivatives(t, 1)[:, 1], axis=-1)
            total += float(np.sum(((b - a) / 2 * w).ravel() * speed))
        else:
            raise SurfmodError(f"out: the DXF holds a {kind} entity, which the section never writes")
    return total


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
    broken = _judged(args.out, s) if suffix == ".dxf" else None
    if broken:
        print(broken)
    if s.faces_skipped:
        from ..occ.topo import faces_of

        for i, reason in sorted(s.faces_skipped.items()):
            print(f"face {i} skipped: {reason}")
        print(f"partial: {len(s.faces_skipped)} of {len(faces_of(shape))} face(s) skipped (OCCT could not intersect "
              f"them); {wrote} with the curves of the others")
    else:
        print(wrote)
    return EXIT_PARTIAL if broken or s.faces_skipped else 0


def _judged(path, s) -> str | None:
    """None when the DXF at ``path`` is as long as the section's OCCT edges, else what
    differs and by how much."""
    from ..occ.sample import edge_length, wire_edges

    ours = dxf_length(path)
    occt = sum(edge_length(e) for w in s.wires for e in wire_edges(w))
    if abs(ours - occt) <= LENGTH_RTOL * occt:
        return None
    return (f"DXF NOT EQUAL TO THE SECTION: its entities are {ours:.12g} long, BRepAlgoAPI_Section's edges "
            f"{occt:.12g} (relative difference {abs(ours - occt) / occt:.2e} > {LENGTH_RTOL:g})")
