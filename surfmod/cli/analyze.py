"""``surfmod analyze PART.step --kind zebra --out z.png``: curvature analysis of a part.

The same concept as :mod:`surfmod.meshing.analyze`, one level up: the command over it.
"""

from __future__ import annotations

from ..errors import SurfmodError

from ..meshing.analyze import analyze

from ..inputs import load_step


def register(sub) -> None:
    p = sub.add_parser("analyze", help="zebra / isophote / curvature map / comb picture of a STEP part")
    p.add_argument("path", help="STEP file")
    p.add_argument("--kind", default="zebra", choices=["zebra", "isophote", "gaussian", "mean", "max_abs", "comb"])
    p.add_argument("--out", required=True, help="PNG to write")
    p.add_argument("--light", default=None, help="light direction x,y,z (default: the view direction)")
    p.add_argument("--stripes", type=int, default=8, help="zebra stripes / isophote levels (default 8)")
    p.add_argument("--resolution", type=int, default=80, help="sampling density (default 80)")
    p.set_defaults(run=run)


def run(args) -> int:
    light = None
    if args.light is not None:
        try:
            light = [float(x) for x in args.light.split(",")]
        except ValueError:
            raise SurfmodError(f"light: expected x,y,z, got {args.light!r}") from None
    shape = load_step(args.path, "path")
    result = analyze(shape, args.kind, args.out, light=light, stripes=args.stripes, resolution=args.resolution)
    print(result)
    print(f"wrote {result.path}")
    return 0
