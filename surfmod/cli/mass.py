"""``surfmod mass FILE.step``: volume, area, centroid and inertia of a STEP solid, checked
against ``BRepGProp``; a disagreement is never printed with exit code 0.

The same concept as :mod:`surfmod.uses.mass`, one level up: the command over it.
"""

from __future__ import annotations

import numpy as np

from .. import tolerances
from ..inputs import to_shape
from ..uses.mass import boundary_ambiguity, mass_properties
from tqdm import tqdm

#: exit code when surfmod and BRepGProp differ by less than the model's own ambiguity
EXIT_AMBIGUOUS = 3
#: exit code when they differ by more (a real disagreement)
EXIT_DISAGREE = 4


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
    scale = max(abs(o.inertia).max(), 1e-300)
    dv = abs(r.volume - o.volume) / o.volume
    print(f"BRepGProp (eps={args.eps:g}) relative differences: volume {dv:.2e}, "
          f"area {abs(r.area - o.area) / o.area:.2e}, centroid {np.abs(r.centroid - o.centroid).max():.2e}, "
          f"inertia {np.abs(r.inertia - o.inertia).max() / scale:.2e}")
    if dv <= tolerances.MASS_AGREEMENT_RTOL:
        return 0
    amb = boundary_ambiguity(solid)
    if amb >= dv:
        print(f"AMBIGUOUS MODEL: the volumes differ by {dv:.2e} (more than {tolerances.MASS_AGREEMENT_RTOL:g}) and the "
              f"model's edges lie off its faces enough to leave the volume open by up to {amb:.2e} (relative); "
              "the file cannot settle the volume closer than that")
        return EXIT_AMBIGUOUS
    print(f"DISAGREEMENT: the volumes differ by {dv:.2e}, more than the model's own ambiguity {amb:.2e}")
    return EXIT_DISAGREE
