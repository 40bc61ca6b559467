"""The ``surfmod convert IN OUT [--check]`` command: one part from one exchange format to another, by
the files' extensions (STEP ``.step``/``.stp``, IGES ``.igs``/``.iges``, OCCT's native
``.brep``; STL ``.stl`` as output, tessellated within ``--tolerance``).

Every write is checked by reading the file back: exit 0 when it gives back what was read
(the number of solids, of faces and of faces in no solid, each solid's orientation,
volume and centroid to 1e-12 relative; for an STL, a closed outward mesh of every solid),
3 when it was written but does not (the lines before say what, and where), 1 on bad input
with nothing written (an STL that is not closed and outward: ``BROKEN:`` lines name the
solids and faces).  ``--check`` also prints the comparison, solid by solid.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from ..atomic import atomic_path, target_path
from ..errors import InsideOutWarning, RoundTripWarning, SurfmodError
from ..io.step_iges import IGES_SUFFIXES, export_iges, export_step, import_iges, import_step, shape_changes
from ..io.stl import export_stl

STEP_SUFFIXES = (".step", ".stp")
#: exit code of a file written whose read-back differs from what was read
EXIT_CHANGED = 3


def register(sub) -> None:
    p = sub.add_parser("convert", help="convert a part between STEP, IGES, BREP and STL, checked by reading it back")
    p.add_argument("input", help="input file: .step/.stp, .igs/.iges or .brep")
    p.add_argument("output", help="output file: .step/.stp, .igs/.iges, .brep or .stl")
    p.add_argument("--check", action="store_true",
                   help="print the read-back comparison per solid (faces, solids, volumes, centroids against IN)")
    p.add_argument("--tolerance", type=float, default=0.01,
                   help="max chordal deviation of an STL output (model units, default 0.01)")
    p.set_defaults(run=run)


def _kind(path: str, name: str, *, output: bool) -> str:
    suffix = Path(path).suffix.lower()
    if suffix in STEP_SUFFIXES:
        return "step"
    if suffix in IGES_SUFFIXES:
        return "iges"
    if suffix == ".brep":
        return "brep"
    if suffix == ".stl" and output:
        return "stl"
    if suffix == ".stl":
        raise SurfmodError(f"{name}: {path} is an STL (triangles, not a B-rep): convert reads STEP, IGES or BREP")
    known = ".step, .stp, .igs, .iges, .brep" + (", .stl" if output else "")
    raise SurfmodError(f"{name}: {path} has the extension {suffix or '(none)'!r}; expected one of {known}")


def read_part(path: str, kind: str):
    """The TopoDS shape of a STEP, IGES or BREP file (STEP in the isolated reader)."""
    from ..occ.step import read_brep

    if kind == "step":
        return import_step(path).wrapped
    if kind == "iges":
        return import_iges(path).wrapped
    if not Path(path).is_file():
        raise SurfmodError(f"path: no such file {path}")
    return read_brep(path)


def _write(shape, out: str, kind: str, tolerance: float):
    """Write ``shape``; the STEP writer's own read-back warning is this command's verdict."""
    from ..occ.step import write_brep

    if kind == "step":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RoundTripWarning)  # compared below, solid by solid
            export_step(shape, out)
    elif kind == "iges":
        export_iges(shape, out, brep=True)  # B-rep solids (entity 186): a solid stays a solid
    elif kind == "brep":
        with atomic_path(target_path(out, "output", (".brep",))) as tmp:
            write_brep(shape, tmp)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RoundTripWarning)  # said by the caller, one line per problem
            return export_stl(shape, out, tolerance)
    return None


def _report(given, again) -> None:
    from ..occ.properties import solid_figures
    from ..occ.topo import faces_of, solids_of

    a, b = solids_of(given), solids_of(again)
    print(f"faces {len(faces_of(given))} -> {len(faces_of(again))}, solids {len(a)} -> {len(b)}")
    for i, (x, y) in enumerate(zip(a, b), 1):
        (va, ca), (vb, cb) = solid_figures(x), solid_figures(y)
        print(f"solid {i}: volume {va:.17g} -> {vb:.17g}, centroid ({', '.join(f'{c:.17g}' for c in ca)}) -> "
              f"({', '.join(f'{c:.17g}' for c in cb)})")


def run(args) -> int:
    tolerance = args.tolerance
    if not tolerance > 0:
        raise SurfmodError(f"--tolerance: expected a positive length, got {tolerance}")
    kind_in = _kind(args.input, "input", output=False)
    kind_out = _kind(args.output, "output", output=True)
    shape = read_part(args.input, kind_in)
    mesh = _write(shape, args.output, kind_out, tolerance)
    if mesh is not None:  # export_stl has read its STL back and judged it
        print(f"{args.output}: {len(mesh.faces)} triangles")
        if mesh.info.get("remeshed"):
            print(f"NOTE: {mesh.info['remeshed']}")
        for line in mesh.info["stl_problems"]:
            print(f"BROKEN: {line}")
        return EXIT_CHANGED if mesh.info["stl_problems"] else 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InsideOutWarning)  # an orientation change is one of the changes below
        again = read_part(args.output, kind_out)
    if args.check:
        _report(shape, again)
    changes = shape_changes(shape, again)
    for line in changes:
        print(f"CHANGED: {line}")
    print(f"{args.output}: {'reads back as written' if not changes else f'{len(changes)} change(s) on reading back'}")
    return EXIT_CHANGED if changes else 0
