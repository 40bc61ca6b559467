"""``surfmod mass FILE.step``: volume, area, centroid and inertia of a STEP solid, checked
against ``BRepGProp``.  Exit 0 when all four agree within ``MASS_AGREEMENT_RTOL`` (one line
says so), or when they differ and an independent reference (:func:`settle`: BRepGProp on
the faces split into ever smaller iso-parametric pieces until it converges, then, where
that split is not exact, BRepGProp's Gauss-Kronrod rule with the moments converged; both
about the same point, within ``REFERENCE_BUDGET`` seconds) confirms surfmod's values (one
line says which side it confirms); 4 when it confirms BRepGProp's, or cannot tell on a
model whose edges close; 3 when it cannot tell and the model itself is ambiguous (its edges
leave the volume open by more than the disagreement, or p-curves stray beyond their
edges' tolerance: they are named).  Edges that stray are named in a note whatever the
verdict, and so are the faces left out (open shells or loose faces beside the solids
enclose no volume).

Given folders or several files, one row per file (volume, area, centroid, exit status and
verdict), to the table or ``--csv`` as each file completes (:mod:`surfmod.cli.batch`).

The same concept as :mod:`surfmod.uses.mass`, one level up: the command over it.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import time
from pathlib import Path

from .. import tolerances
from ..errors import SurfmodError
from ..inputs import to_shape
from ..uses.mass import boundary_ambiguity, mass_properties
from .batch import add_batch_arguments, batch_run, step_files
from tqdm import tqdm

#: exit code when surfmod and BRepGProp differ by less than the model's own ambiguity
EXIT_AMBIGUOUS = 3
#: exit code when they differ by more (a real disagreement)
EXIT_DISAGREE = 4
#: seconds the refined reference may take to settle a disagreement (each refinement's
#: cost is estimated from the one before it, before it starts)
REFERENCE_BUDGET = 60.0


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
    """``surfmod mass PART.step``: the verdict on one file, printed; ``args.result`` is
    surfmod's ``MassProperties``."""
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
    from ..occ.properties import relative_differences
    from ..occ.solids import left_out_faces

    left = left_out_faces(shape)
    if left:  # an open shell beside the solids: measured it would be a guess, so it is named instead
        print(f"NOTE: {len(left)} face(s) outside every closed solid (open shells or loose faces) are left out, "
              f"they enclose no volume: faces {', '.join(map(str, left[:10]))}{' ...' if len(left) > 10 else ''}")
    from ..occ.strays import edge_strays

    limit = tolerances.MASS_AGREEMENT_RTOL
    diffs = relative_differences(r, o)
    print(f"BRepGProp (eps={args.eps:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items())
          + f" (limit {limit:g}; centroid relative to volume^(1/3), inertia to its largest entry)")
    off = {k: v for k, v in diffs.items() if not v <= limit}
    if off:
        # BRepGProp's adaptive eps bounds the volume's error; its first and second moments
        # converge more slowly (a cube and a cylinder: inertia 1.1e-6 off at eps 1e-9, 3.4e-8
        # at 1e-11, 8.2e-10 at 1e-13, towards surfmod's): judge everything at a finer eps
        fine = max(args.eps * 1e-4, 1e-14)
        o = mass_properties(solid, args.density, method="occt", eps=fine)
        diffs = relative_differences(r, o)
        print(f"BRepGProp (eps={fine:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items()))
        off = {k: v for k, v in diffs.items() if not v <= limit}
    # measured on the file's shape, so edges and faces carry the file's numbers, as the
    # faces left out do; edges of those faces bound no volume and do not count
    outside = set(left)
    strays = sorted((e for e in edge_strays(shape) if e.ambiguous and outside.isdisjoint(e.faces)),
                    key=lambda e: -max(e.stray, e.gap))
    named = ", ".join(f"edge {e.edge} of faces {'/'.join(map(str, e.faces))} ({max(e.stray, e.gap):.2e} > tol "
                      f"{e.tolerance:.1e})" for e in strays[:5]) + (" ..." if len(strays) > 5 else "")
    amb = None
    if strays:  # whatever the verdict: the digits below the strays are the file's, not the part's
        amb = boundary_ambiguity(solid)
        print(f"NOTE: {len(strays)} edge(s) have p-curves straying beyond their own tolerance: {named}; the file's "
              f"edges leave its volume open by up to {amb:.2e} (relative): digits beyond that are the file's, not "
              "the part's")
    if not off:
        print(f"AGREE: volume, area, centroid and inertia all agree with BRepGProp within {limit:g}")
        return 0
    worst = max(off.values())
    side, line = settle(solid, r, o, sorted(off), limit, args.density)
    print(line)
    if side == "surfmod":
        return 0
    differ = f"{', '.join(off)} differ{'s' if len(off) == 1 else ''} from BRepGProp by up to {worst:.2e}"
    if side is None:
        amb = boundary_ambiguity(solid) if amb is None else amb
        if strays or amb >= worst:
            print(f"AMBIGUOUS MODEL: {differ} (more than {limit:g}); the model's edges leave its volume open by up to "
                  f"{amb:.2e} (relative) and {len(strays)} edge(s) have p-curves straying beyond their own tolerance"
                  + (f": {named}" if strays else ""))
            return EXIT_AMBIGUOUS
        print(f"DISAGREEMENT: {differ}, more than the model's own ambiguity {amb:.2e}, and no edge strays beyond "
              "its tolerance")
        return EXIT_DISAGREE
    print(f"DISAGREEMENT: {differ}, and the reference confirms BRepGProp's")
    return EXIT_DISAGREE


def settle(solid, r, o, names, limit, density: float = 1.0):
    """``(side, line)``: which of surfmod ``r`` and BRepGProp ``o`` an independent reference
    confirms for the differing quantities ``names``: ``"surfmod"`` when surfmod is within
    ``limit`` of it and BRepGProp is not, by more than the reference's own error estimate;
    ``"occt"`` the other way round; ``None`` (with the reasons) when no reference can tell
    within ``REFERENCE_BUDGET`` seconds.  The references, in turn until one tells: BRepGProp
    on the faces split until it converges (:func:`surfmod.occ.refined_props.refined_props`),
    then BRepGProp's Gauss–Kronrod rule with the moments converged
    (:func:`surfmod.occ.kronrod_props.kronrod_props_within`, for solids whose split is not
    exact), both about the solid's vertex mean, the point surfmod takes (``density`` scales
    the references' inertia as it scales theirs)."""
    start = time.perf_counter()
    lines = []
    for reference in (_split_reference, _kronrod_reference):
        try:
            ref, how, errors = reference(solid, names, REFERENCE_BUDGET - (time.perf_counter() - start))
        except SurfmodError as exc:
            lines.append(f"REFERENCE SKIPPED: {exc}")
            continue
        side, line = _verdict(dataclasses.replace(ref, inertia=density * ref.inertia), r, o, names, limit, how, errors)
        lines.append(line)
        if side is not None:  # the lines of the references that could not tell come first
            return side, "\n".join(lines)
    return None, "\n".join(lines)


def _split_reference(solid, names, seconds):
    """``(reference, how it is named, its error per quantity)``: the faces split."""
    from ..occ.refined_props import refined_props

    ref = refined_props(solid, budget=seconds)
    return ref, f"BRepGProp on the faces split {ref.splits} x {ref.splits}", ref.changes


def _kronrod_reference(solid, names, seconds):
    """The same for the Gauss-Kronrod rule: one error estimate for every quantity."""
    from ..occ.kronrod_props import kronrod_props_within

    ref = kronrod_props_within(solid, seconds)
    return ref, "BRepGProp's Gauss-Kronrod rule", dict.fromkeys(names, ref.error)


def _verdict(ref, r, o, names, limit, how, errors):
    from ..occ.properties import relative_differences

    diffs = {"surfmod": relative_differences(r, ref), "occt": relative_differences(o, ref)}
    sides = set()
    for k in names:
        mine, theirs, est = diffs["surfmod"][k], diffs["occt"][k], errors[k]
        if mine + est <= limit < theirs - est:
            sides.add("surfmod")
        elif theirs + est <= limit < mine - est:
            sides.add("occt")
        else:
            sides.add(None)
    detail = ", ".join(f"{k}: surfmod {diffs['surfmod'][k]:.2e}, BRepGProp {diffs['occt'][k]:.2e} (its error "
                       f"{errors[k]:.1e})" for k in names)
    if sides == {"surfmod"}:
        return "surfmod", f"REFERENCE CONFIRMS SURFMOD: {how} agrees with surfmod, not with plain BRepGProp ({detail})"
    if sides == {"occt"}:
        return "occt", f"REFERENCE CONFIRMS BREPGPROP: {how} agrees with plain BRepGProp, not surfmod ({detail})"
    return None, f"REFERENCE UNDECIDED: {how} cannot tell the two apart ({detail})"
