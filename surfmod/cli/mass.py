"""``surfmod mass FILE.step``: volume, area, centroid and inertia of a STEP solid, checked
against ``BRepGProp``, with the verdict of an independent reference where they differ
(:mod:`surfmod.uses.mass_reference`, within ``REFERENCE_BUDGET`` seconds) and exit 0, 3 or
4; folders and several files give one row per file (:mod:`surfmod.cli.batch`).

The same concept as :mod:`surfmod.uses.mass`, one level up: the command over it.
See :doc:`/guide/uses` (section "Checked against BRepGProp and the references").
"""

from __future__ import annotations

import argparse
import contextlib
import io
from pathlib import Path

from ..errors import SurfmodError
from ..inputs import to_shape
from ..readback.strays import edge_strays
from ..uses import mass_reference
from ..uses.mass import boundary_ambiguity, mass_properties
from ..uses.mass_reference import EXIT_AMBIGUOUS, EXIT_DISAGREE
from .batch import add_batch_arguments, batch_run, step_files
from tqdm import tqdm


def register(sub) -> None:
    p = sub.add_parser("mass", help="mass properties of a STEP solid (NumPy quadrature, checked against BRepGProp)")
    p.add_argument("path", nargs="+", help="STEP file, or several files or folders (one row per file)")
    p.add_argument("--density", type=float, default=1.0, help="density (default 1)")
    p.add_argument("--eps", type=float, default=1e-9, help="BRepGProp relative tolerance for the cross-check")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    add_batch_arguments(p)
    p.set_defaults(run=run)


MASS_COLUMNS = [("file", "<36.36"), ("exit", ">4d"), ("volume", ">14.7g"), ("area", ">14.7g"), ("cx", ">12.6g"),
                ("cy", ">12.6g"), ("cz", ">12.6g"), ("verdict", "<")]
#: the first words of the line that gives the command's verdict
VERDICTS = ("AGREE", "REFERENCE", "AMBIGUOUS", "DISAGREEMENT")


def mass_failed(path, message) -> tuple:
    """The one row of a file ``surfmod mass`` could not measure (exit 1) or skipped."""
    nan = float("nan")
    return (str(path), 1, nan, nan, nan, nan, nan, message)


def mass_file(path, density: float = 1.0, eps: float = 1e-9) -> list[tuple]:
    """``surfmod mass`` on one file as one row ``(file, exit status, volume, area, cx,
    cy, cz, verdict)``; the verdict is the command's verdict line (with its NOTE lines
    after it), or the error of a file it could not measure."""
    args = argparse.Namespace(path=str(path), density=density, eps=eps, no_progress=True)
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            code = run_one(args)
    except SurfmodError as exc:
        return [mass_failed(path, f"error: {' '.join(str(exc).split())}")]
    lines = printed.getvalue().splitlines()
    verdict = [ln for ln in lines if ln.startswith((*VERDICTS, "NOTE"))]
    r = args.result
    return [(str(path), code, r.volume, r.area, *map(float, r.centroid), " | ".join(verdict))]


def run(args) -> int:
    if len(args.path) == 1 and not Path(args.path[0]).is_dir() and not args.csv and not args.scheduler:
        args.path = args.path[0]
        return run_one(args)
    args.files = step_files(args.path)
    codes = []
    for row, _ in batch_run(args, mass_file, {"density": args.density, "eps": args.eps}, MASS_COLUMNS, "mass",
                            mass_failed):
        codes.append(int(row[1]))
    resumed = f" ({args.skipped} already in {args.csv})" if args.skipped else ""
    agree = sum(c == 0 for c in codes)
    print(f"{agree} of {len(codes)} file(s) settled (exit 0){resumed}" + (f"; rows in {args.csv}" if args.csv else ""))
    # the worst file's status: a disagreement over an ambiguity over an unreadable file
    return max(codes, key=lambda c: (c == EXIT_DISAGREE, c == EXIT_AMBIGUOUS, c == 1)) if codes else 0


def run_one(args) -> int:
    """``surfmod mass PART.step``: the verdict on one file (:func:`surfmod.uses.mass_reference.judge`),
    printed; ``args.result`` is surfmod's ``MassProperties``."""
    with tqdm(total=3, desc="mass", unit="step", disable=args.no_progress) as bar:
        shape = to_shape(args.path, "path")
        solid = to_shape(shape, "path", solid=True)
        bar.update()
        # BRepGProp below is the independent check: the second quadrature pass is not needed
        r = args.result = mass_properties(solid, args.density, estimate_error=False)
        bar.update()
        o = mass_properties(solid, args.density, method="occt", eps=args.eps)
        bar.update()
    print(r)
    return mass_reference.judge(shape, solid, r, o, eps=args.eps, density=args.density,
                                occt=lambda eps: mass_properties(solid, args.density, method="occt", eps=eps),
                                ambiguity=lambda: boundary_ambiguity(solid), strays=edge_strays(shape))
