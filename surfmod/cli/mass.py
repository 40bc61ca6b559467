"""``surfmod mass FILE.step``: volume, area, centroid and inertia of a STEP solid, checked
against ``BRepGProp``.  Exit 0 when all four agree within ``MASS_AGREEMENT_RTOL`` (one line
says so), or when they differ and the independent reference
(:mod:`surfmod.occ.refined_props`: BRepGProp on the faces split into ever smaller
iso-parametric pieces until it converges, about the same point, within
``REFERENCE_BUDGET`` seconds) confirms surfmod's values (one line says which side it
confirms); 4 when it confirms BRepGProp's, or cannot tell on a model whose edges close;
3 when it cannot tell and the model itself is ambiguous (its edges leave the volume open
by more than the disagreement, or p-curves stray beyond their edges' tolerance: they are
named).  Edges that stray are named in a note whatever the verdict.

The same concept as :mod:`surfmod.uses.mass`, one level up: the command over it.
"""

from __future__ import annotations

import dataclasses

from .. import tolerances
from ..errors import SurfmodError
from ..inputs import to_shape
from ..uses.mass import boundary_ambiguity, mass_properties
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
    p.add_argument("path", help="STEP file")
    p.add_argument("--density", type=float, default=1.0, help="density (default 1)")
    p.add_argument("--eps", type=float, default=1e-9, help="BRepGProp relative tolerance for the cross-check")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    with tqdm(total=3, desc="mass", unit="step", disable=args.no_progress) as bar:
        solid = to_shape(args.path, "path", solid=True)
        bar.update()
        # BRepGProp below is the independent check: the second quadrature pass is not needed
        r = mass_properties(solid, args.density, estimate_error=False)
        bar.update()
        o = mass_properties(solid, args.density, method="occt", eps=args.eps)
        bar.update()
    print(r)
    from ..occ.properties import relative_differences
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
    strays = sorted((e for e in edge_strays(solid) if e.ambiguous), key=lambda e: -max(e.stray, e.gap))
    named = ", ".join(f"edge {e.edge} of faces {'/'.join(map(str, e.faces))} ({max(e.stray, e.gap):.2e} > tol "
                      f"{e.tolerance:.1e})" for e in strays[:5]) + (" ..." if len(strays) > 5 else "")
    if strays:  # whatever the verdict: the digits below the strays are the file's, not the part's
        print(f"NOTE: {len(strays)} edge(s) have p-curves straying beyond their own tolerance: {named}")
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
        amb = boundary_ambiguity(solid)
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
    """``(side, line)``: which of surfmod ``r`` and BRepGProp ``o`` the refined reference
    (:func:`surfmod.occ.refined_props.refined_props`, about the solid's vertex mean: the
    point both take) confirms for the differing quantities ``names``: ``"surfmod"`` when
    surfmod is within ``limit`` of it and BRepGProp is not, by more than the reference's own
    error estimate; ``"occt"`` the other way round; ``None`` (with the reason) when it
    cannot tell or would take more than ``REFERENCE_BUDGET`` seconds (``density`` scales
    the reference's inertia as it scales theirs)."""
    from ..occ.properties import relative_differences
    from ..occ.refined_props import refined_props

    try:
        ref = refined_props(solid, budget=REFERENCE_BUDGET)
    except SurfmodError as exc:
        return None, f"REFERENCE SKIPPED: {exc}"
    ref = dataclasses.replace(ref, inertia=density * ref.inertia)
    diffs = {"surfmod": relative_differences(r, ref), "occt": relative_differences(o, ref)}
    sides = set()
    for k in names:
        mine, theirs, est = diffs["surfmod"][k], diffs["occt"][k], ref.changes[k]
        if mine + est <= limit < theirs - est:
            sides.add("surfmod")
        elif theirs + est <= limit < mine - est:
            sides.add("occt")
        else:
            sides.add(None)
    how = f"BRepGProp on the faces split {ref.splits} x {ref.splits}"
    detail = ", ".join(f"{k}: surfmod {diffs['surfmod'][k]:.2e}, BRepGProp {diffs['occt'][k]:.2e} (its error "
                       f"{ref.changes[k]:.1e})" for k in names)
    if sides == {"surfmod"}:
        return "surfmod", f"REFERENCE CONFIRMS SURFMOD: {how} agrees with surfmod, not with plain BRepGProp ({detail})"
    if sides == {"occt"}:
        return "occt", f"REFERENCE CONFIRMS BREPGPROP: {how} agrees with plain BRepGProp, not surfmod ({detail})"
    return None, f"REFERENCE UNDECIDED: {how} cannot tell the two apart ({detail})"

