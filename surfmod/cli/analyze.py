"""``surfmod analyze PART.step --kind zebra --out z.png``: curvature analysis of a part.

The same concept as :mod:`surfmod.meshing.analyze`, one level up: the command over it.
A face OCCT cannot triangulate (or surfmod cannot read back) does not stop the picture:
it is named, the other faces are drawn, and the command exits 3 (partial).
"""

from __future__ import annotations

import numpy as np

from ..errors import SurfmodError
from ..inputs import read_step_file
from ..meshing.analyze import analyze
from ..readback import from_face
from . import EXIT_PARTIAL


def register(sub) -> None:
    p = sub.add_parser("analyze", help="zebra / isophote / curvature map / comb picture of a STEP part")
    p.add_argument("path", help="STEP file")
    p.add_argument("--kind", default="zebra", choices=["zebra", "isophote", "gaussian", "mean", "max_abs", "comb"])
    p.add_argument("--out", required=True, help="PNG to write")
    p.add_argument("--light", default=None, help="light direction x,y,z (default: the view direction)")
    p.add_argument("--stripes", type=int, default=8, help="zebra stripes / isophote levels (default 8)")
    p.add_argument("--resolution", type=int, default=80, help="sampling density (default 80)")
    p.set_defaults(run=run)


def failing_faces(faces, resolution: int) -> dict:
    """``{face index: reason}`` for the faces :func:`surfmod.analyze` cannot sample: the
    read-back and OCCT's triangulation of the trimmed region, at the density analyze uses
    (the part's diagonal over ``resolution``).  One pass, so its work is one
    triangulation a face."""
    from ..occ.mesh import face_uv_triangles
    from ..occ.properties import bounding_box
    from ..occ.topo import compound

    box = bounding_box(compound(faces))
    target = float(np.linalg.norm(box[1] - box[0])) / resolution
    failed = {}
    for i, face in enumerate(faces):
        try:
            from_face(face)
            face_uv_triangles(face, target, 0.1)
        except SurfmodError as exc:
            failed[i] = " ".join(str(exc).split())
    return failed


def run(args) -> int:
    from ..occ.topo import faces_of

    light = None
    if args.light is not None:
        try:
            light = [float(x) for x in args.light.split(",")]
        except ValueError:
            raise SurfmodError(f"light: expected x,y,z, got {args.light!r}") from None
    shape = read_step_file(args.path, "path")
    options = dict(light=light, stripes=args.stripes, resolution=args.resolution)
    try:
        result, failed = analyze(shape, args.kind, args.out, **options), {}
    except SurfmodError as whole:
        # which faces?  screened one by one only when the whole part failed, so a part
        # that analyses is triangulated once
        faces = faces_of(shape)
        failed = failing_faces(faces, args.resolution) if args.resolution >= 3 else {}
        if not failed or len(failed) == len(faces):
            raise whole
        # the faces drawn no longer close a solid: both of their sides are shown
        result = analyze([f for i, f in enumerate(faces) if i not in failed], args.kind, args.out, **options)
    print(result)
    if failed:
        for i, reason in failed.items():
            print(f"face {i} skipped: {reason}")
        total = len(result.patches) + len(failed)
        print(f"partial: {len(failed)} of {total} face(s) skipped (OCCT could not triangulate or read them); "
              f"wrote {result.path} with the other {len(result.patches)}")
        return EXIT_PARTIAL
    print(f"wrote {result.path}")
    return 0
