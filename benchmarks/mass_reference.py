"""surfmod's mass properties against an independent reference and BRepGProp on every valid
solid of the corpus: ``python -m benchmarks.mass_reference [--reference refined|cuts]
[--budget S] [FILE ...]`` prints one row per solid.

``refined`` (default) is :func:`surfmod.uses.mass_reference.refined_props` (BRepGProp on the faces split
until it converges, seconds per solid; ``tests/test_mass_reference.py`` runs it on every
corpus solid), ``cuts`` is ``tests/twins/moment_reference.py`` (the solid cut by hundreds
of planes, seconds to minutes per solid, a script's work rather than a test's).  Columns:
centroid differences relative to volume^(1/3), inertia differences relative to its
largest entry, for surfmod-vs-reference (``sm``), BRepGProp-vs-reference (``occ``, eps
1e-12) and surfmod-vs-BRepGProp (``sm-occ``); the reference's own error estimates
(``est``); for ``cuts`` its largest cut defect, diagonal check and planes, for ``refined``
its last split.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from OCP.BRepCheck import BRepCheck_Analyzer

import surfmod as sm
from surfmod.errors import SurfmodError
from surfmod.occ.properties import gprops
from twins.moment_reference import moment_reference
from surfmod.uses.mass_reference import refined_props
from surfmod.occ.topo import faces_of, solids_of
from surfmod.uses.mass import mass_properties

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"


def compare(solid, budget, reference="refined"):
    t0 = time.perf_counter()
    mine = mass_properties(solid, estimate_error=False)
    t1 = time.perf_counter()
    o = gprops(solid, 1e-12)
    ref = (refined_props(solid, budget=budget) if reference == "refined"
           else moment_reference(solid, o["volume"], budget=budget))
    length, big = ref.volume ** (1 / 3), np.abs(ref.inertia).max()
    if reference == "refined":
        c_est, i_est = ref.changes["centroid"], ref.changes["inertia"]
        extra = {"splits": ref.splits}
    else:
        c_est, i_est = ref.centroid_error / length, ref.inertia_error / big
        extra = {"defect": ref.defect, "check": ref.consistency, "planes": ref.planes}

    def dc(c):
        return float(np.abs(np.asarray(c) - ref.centroid).max()) / length

    def di(i):
        return float(np.abs(np.asarray(i) - ref.inertia).max()) / big

    return {
        "vol sm-occ": abs(mine.volume - o["volume"]) / o["volume"],
        "c sm": dc(mine.centroid), "c occ": dc(o["centroid"]), "c est": c_est,
        "c sm-occ": float(np.abs(np.asarray(mine.centroid) - o["centroid"]).max()) / length,
        "I sm": di(mine.inertia), "I occ": di(o["inertia"]), "I est": i_est,
        **extra, "t sm": t1 - t0, "t ref": ref.seconds,
    }


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("files", nargs="*", help="STEP files (default: the corpus)")
    p.add_argument("--reference", choices=("refined", "cuts"), default="refined", help="which reference (default refined)")
    p.add_argument("--budget", type=float, default=600.0, help="seconds per solid for the reference")
    p.add_argument("--max-faces", type=int, default=400, help="skip solids with more faces (stated)")
    p.add_argument("--solids", type=int, default=None, help="only the first N solids of each file")
    args = p.parse_args(argv)
    files = [Path(f) for f in args.files] or sorted(
        x for x in CORPUS.glob("*") if x.suffix.lower() in (".step", ".stp"))
    keys = None
    for path in files:
        for i, solid in enumerate(solids_of(sm.import_step(path).wrapped)[:args.solids]):
            name = f"{path.name}#{i}"
            nf = len(faces_of(solid))
            if not BRepCheck_Analyzer(solid).IsValid():
                print(f"{name}: skipped, BRepCheck calls it invalid", flush=True)
                continue
            if nf > args.max_faces:
                print(f"{name}: skipped, {nf} faces > --max-faces {args.max_faces}", flush=True)
                continue
            try:
                row = compare(solid, args.budget, args.reference)
            except SurfmodError as exc:
                print(f"{name}: {nf} faces, no reference: {exc}", flush=True)
                continue
            if keys is None:
                keys = list(row)
                print("solid faces " + " ".join(keys), flush=True)
            cells = (f"{row[k]:.2e}" if isinstance(row[k], float) else str(row[k]) for k in keys)
            print(f"{name} {nf} " + " ".join(cells), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
