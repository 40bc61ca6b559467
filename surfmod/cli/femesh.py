"""``surfmod femesh FILE.step --size S --out mesh.msh``: gmsh FE mesh via meshio.

The same concept as :mod:`surfmod.uses.femesh`, one level up: the command over it.
"""

from __future__ import annotations

from ..atomic import target_path
from ..uses.femesh import FORMATS, export_fe_mesh, fe_mesh
from tqdm import tqdm


def register(sub) -> None:
    p = sub.add_parser("femesh", help="finite element mesh of a STEP part (gmsh; .msh/.vtu/.inp)")
    p.add_argument("path", help="STEP file")
    p.add_argument("--size", type=float, required=True, help="target element size")
    p.add_argument("--out", required=True, help="output .msh, .vtu or .inp")
    p.add_argument("--order", type=int, default=1, choices=(1, 2))
    p.add_argument("--kind", default="volume", choices=("volume", "surface"))
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def run(args) -> int:
    target_path(args.out, "out", tuple(FORMATS))
    with tqdm(total=2, desc="femesh", unit="step", disable=args.no_progress) as bar:
        m = fe_mesh(args.path, args.size, args.order, args.kind)
        bar.update()
        export_fe_mesh(m, args.out)
        bar.update()
    print(m)
    print(f"wrote {args.out}")
    return 0
