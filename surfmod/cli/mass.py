"""``surfmod mass FILE.step``: volume, area, centroid and inertia of a STEP solid, checked
against ``BRepGProp``; exit 0 when all four agree within ``MASS_AGREEMENT_RTOL`` (one
line says so), or when only the centroid or inertia differ and the independent moment
reference (:mod:`surfmod.occ.moment_reference`, volumes of the solid cut by planes,
within ``REFERENCE_BUDGET`` seconds) confirms surfmod's (one line says which side it
confirms); 3 when the model itself is ambiguous (its edges leave the volume that open, or
p-curves stray beyond their edges' tolerance: they are named), 4 otherwise.

The same concept as :mod:`surfmod.uses.mass`, one level up: the command over it.
"""

from __future__ import annotations

import numpy as np

from .. import tolerances
from ..errors import SurfmodError
from ..inputs import to_shape
from ..uses.mass import boundary_ambiguity, mass_properties
from tqdm import tqdm

#: exit code when surfmod and BRepGProp differ by less than the model's own ambiguity
EXIT_AMBIGUOUS = 3
#: exit code when they differ by more (a real disagreement)
EXIT_DISAGREE = 4
#: seconds the moment reference may take to settle a centroid or inertia disagreement
#: (its cost is estimated first from its planes and the solid's faces, then bounded)
REFERENCE_BUDGET = 30.0


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
    limit = tolerances.MASS_AGREEMENT_RTOL
    diffs = relative_differences(r, o)
    print(f"BRepGProp (eps={args.eps:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items())
          + f" (limit {limit:g}; centroid relative to volume^(1/3), inertia to its largest entry)")
    off = {k: v for k, v in diffs.items() if not v <= limit}
    if off and "volume" not in off:
        # BRepGProp's adaptive eps bounds the volume's error; its first and second moments
        # converge more slowly (a cube and a cylinder: inertia 1.1e-6 off at eps 1e-9, 3.4e-8
        # at 1e-11, 8.2e-10 at 1e-13, towards surfmod's): judge them at a finer eps
        fine = max(args.eps * 1e-4, 1e-14)
        o = mass_properties(solid, args.density, method="occt", eps=fine)
        diffs = relative_differences(r, o)
        print(f"BRepGProp (eps={fine:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items()))
        off = {k: v for k, v in diffs.items() if not v <= limit}
    if not off:
        print(f"AGREE: volume, area, centroid and inertia all agree with BRepGProp within {limit:g}")
        return 0
    from ..occ.strays import edge_strays

    worst = max(off.values())
    amb = boundary_ambiguity(solid)
    strays = [e for e in edge_strays(solid) if e.ambiguous]
    named = ", ".join(f"edge {e.edge} of faces {'/'.join(map(str, e.faces))} ({max(e.stray, e.gap):.2e} > tol "
                      f"{e.tolerance:.1e})" for e in sorted(strays, key=lambda e: -max(e.stray, e.gap))[:5])
    if strays or amb >= worst:
        print(f"AMBIGUOUS MODEL: {', '.join(off)} differ{'s' if len(off) == 1 else ''} from BRepGProp by up to "
              f"{worst:.2e} (more than {limit:g}); the model's edges leave its volume open by up to {amb:.2e} "
              f"(relative) and {len(strays)} edge(s) have p-curves straying beyond their own tolerance"
              + (f": {named}{' ...' if len(strays) > 5 else ''}" if strays else ""))
        return EXIT_AMBIGUOUS
    if set(off) <= {"centroid", "inertia"}:
        # a clean model whose volumes agree: the reference built on volumes alone can say
        # which side's moments are right
        side, line = settle(solid, r, o, sorted(off), limit)
        print(line)
        if side == "surfmod":
            return 0
    print(f"DISAGREEMENT: {', '.join(off)} differ{'s' if len(off) == 1 else ''} from BRepGProp by up to {worst:.2e}, "
          f"more than the model's own ambiguity {amb:.2e}, and no edge strays beyond its tolerance")
    return EXIT_DISAGREE


def settle(solid, r, o, names, limit):
    """``(side, line)``: which of surfmod ``r`` and BRepGProp ``o`` the independent moment
    reference confirms for the differing quantities ``names`` (centroid, inertia):
    ``"surfmod"`` when surfmod is within ``limit`` of it and BRepGProp is not, by more than
    the reference's own error estimate; ``"occt"`` the other way round; ``None`` (with the
    reason) when it cannot tell or would take more than ``REFERENCE_BUDGET`` seconds."""
    from ..occ.moment_reference import estimated_seconds, moment_reference

    cost = estimated_seconds(solid)
    if cost > REFERENCE_BUDGET:
        return None, (f"REFERENCE SKIPPED: the independent moment reference would take about {cost:.0f} s "
                      f"(more than {REFERENCE_BUDGET:g} s) on this solid")
    try:
        ref = moment_reference(solid, o.volume, budget=REFERENCE_BUDGET)
    except SurfmodError as exc:
        return None, f"REFERENCE SKIPPED: {exc}"
    length = ref.volume ** (1 / 3)
    big = float(np.abs(ref.inertia).max())
    diff = {"centroid": lambda x: float(np.abs(np.asarray(x.centroid) - ref.centroid).max()) / length,
            "inertia": lambda x: float(np.abs(np.asarray(x.inertia) - ref.inertia).max()) / big}
    est = {"centroid": ref.centroid_error / length, "inertia": ref.inertia_error / big}
    sides = set()
    for k in names:
        mine, theirs = diff[k](r), diff[k](o)
        if mine + est[k] <= limit < theirs - est[k]:
            sides.add("surfmod")
        elif theirs + est[k] <= limit < mine - est[k]:
            sides.add("occt")
        else:
            sides.add(None)
    detail = ", ".join(f"{k}: surfmod {diff[k](r):.2e}, BRepGProp {diff[k](o):.2e} (its error {est[k]:.1e})"
                       for k in names)
    if sides == {"surfmod"}:
        return "surfmod", ("REFERENCE CONFIRMS SURFMOD: the independent moment reference agrees with surfmod, "
                           f"not BRepGProp ({detail})")
    if sides == {"occt"}:
        return "occt", ("REFERENCE CONFIRMS BREPGPROP: the independent moment reference agrees with BRepGProp, "
                        f"not surfmod ({detail})")
    return None, f"REFERENCE UNDECIDED: the independent moment reference cannot tell the two apart ({detail})"


def relative_differences(r, o) -> dict:
    """surfmod's mass properties ``r`` against BRepGProp's ``o``: volume and area relative,
    the centroid relative to the volume's cube root, the inertia to its largest entry."""
    length = max(abs(o.volume), 1e-300) ** (1 / 3)
    return {
        "volume": abs(r.volume - o.volume) / max(abs(o.volume), 1e-300),
        "area": abs(r.area - o.area) / max(abs(o.area), 1e-300),
        "centroid": float(np.abs(np.asarray(r.centroid) - np.asarray(o.centroid)).max()) / length,
        "inertia": float(np.abs(np.asarray(r.inertia) - np.asarray(o.inertia)).max()) / max(abs(np.asarray(o.inertia)).max(), 1e-300),
    }
