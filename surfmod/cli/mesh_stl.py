"""``surfmod mesh FILE.step --tolerance T --out part.stl [--strict]``: STL for CAM and
slicers, measured against the B-rep; faces whose model is itself off by more than the
tolerance are reported (or refused with ``--strict``).  The STL is read back before exit
0: exit 3 when a solid's triangles are not closed, 2-manifold and outward, or a face's
triangles stray where its nodes and tolerance do not (``BROKEN:`` lines name them).
Over folders, each file's row carries the same verdict and its exit status, and the
command exits 3 when any file's STL broke a promise (:func:`surfmod.cli.batch.run_mesh`).

The mesh is BRepMesh's, every triangle measured against its exact face and refined where
the meshing, not the model, is the cause (:func:`surfmod.meshing.brep.tessellate_shape`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

from ..errors import RoundTripWarning
from ..inputs import read_step_file
from ..io.stl import export_stl
from ..meshing.brep import describe_faces
from .batch import EXIT_BROKEN, add_batch_arguments, is_batch, run_mesh


def register(sub) -> None:
    p = sub.add_parser("mesh", help="tessellate a STEP file to a watertight STL within a chordal tolerance")
    p.add_argument("step", nargs="+", help="input STEP file(s) or folders (searched recursively for .step/.stp)")
    p.add_argument("--tolerance", type=float, default=0.01, help="max chordal deviation (model units, default 0.01)")
    p.add_argument("--out", help="output STL (default: beside the input); with several files a folder")
    p.add_argument("--ascii", action="store_true", help="ASCII STL instead of binary")
    p.add_argument("--strict", action="store_true",
                   help="refuse (exit non-zero, no file) when a face of the model is itself off by more than the "
                        "tolerance, instead of writing the STL and reporting those faces")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    add_batch_arguments(p)
    p.set_defaults(run=run)


def run(args) -> int:
    if is_batch(args):
        return run_mesh(args)
    args.step = args.step[0]
    # the kernel's shape, not a build123d one: the STL needs nothing of build123d, whose
    # import is most of a fresh process's start-up
    shape = read_step_file(args.step, "step")
    out = Path(args.out) if args.out else Path(args.step).with_suffix(".stl")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RoundTripWarning)  # said below, one line per problem
        mesh = export_stl(shape, out, tolerance=args.tolerance, ascii=args.ascii, strict=args.strict,
                          progress=not args.no_progress)
    watertight, consistent = mesh.edge_use()
    dev = mesh.info.get("max_deviation")
    print(f"{out}: {len(mesh.faces)} triangles, {len(mesh.vertices)} vertices, "
          f"watertight {watertight}, winding consistent {consistent}"
          + (f", measured max deviation {dev:.3g}" if dev is not None else ""))
    skipped = mesh.info.get("faces_not_meshed", [])
    if skipped:
        print(f"NOTE: {len(skipped)} face(s) of open shells BRepMesh cannot triangulate are left out: faces "
              f"{', '.join(map(str, skipped[:10]))}{' ...' if len(skipped) > 10 else ''} (--strict refuses them)")
    opened = mesh.info.get("open_faces", 0) - len(skipped)
    if opened:
        print(f"NOTE: {opened} face(s) lie in no closed shell (open shells or loose faces): "
              "the STL stays open along their free edges, as the model is")
    report = [r for r in mesh.info.get("faces_over_tolerance", []) if r.get("cause") != "mesh"]
    if report:
        print(f"{len(report)} face(s) deviate more than {args.tolerance:g} and a finer mesh does not bring them "
              f"closer: the model's own error (its nodes or its tolerance are that far off); --strict refuses "
              f"such parts")
        print(describe_faces(report))
    if mesh.info.get("remeshed"):
        print(f"NOTE: {mesh.info['remeshed']}")
    # the STL read back: every solid closed, 2-manifold, outward; no meshing failure
    problems = mesh.info.get("stl_problems", [])
    for line in problems:
        print(f"BROKEN: {line}")
    return EXIT_BROKEN if problems else 0
