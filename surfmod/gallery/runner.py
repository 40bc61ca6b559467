"""Run the gallery: build, cross-check, export STEP + STL (+ PNG when rendering exists)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import SurfmodError
from ..io.step_iges import export_step
from ..io.stl import export_stl
from ..meshing.render import render
from ..surface import Surface
from ..occt_crosscheck import crosscheck
from . import Entry, entries
from tqdm import tqdm


@dataclass
class GalleryRow:
    name: str
    entity: str
    construct: str
    mode: str
    max_deviation: float
    passed: bool
    note: str = ""


def run_entry(e: Entry, outdir: Path) -> GalleryRow:
    try:
        obj = e.build()
        if isinstance(obj, Surface):
            result = crosscheck(obj)
            construct = obj.occt_construct
            mode, dev, ok = result.mode, result.max_deviation, result.passed
        else:  # a build123d shape (solids from subdivision, parts): checked face by face
            # many faces: a coarser grid per face keeps the gallery quick; still includes knots
            results = [crosscheck(f, samples=16) for f in obj.faces()]
            construct = type(obj).__name__
            mode = "per-face"
            dev = max(r.max_deviation for r in results)
            ok = all(r.passed for r in results)
        export_step(obj, outdir / f"{e.name}.step")
        export_stl(obj, outdir / f"{e.name}.stl", tolerance=0.01)
        render([obj], outdir / f"{e.name}.png")
        return GalleryRow(e.name, e.entity, construct, mode, dev, ok)
    except SurfmodError as exc:
        return GalleryRow(e.name, e.entity, "-", "error", float("nan"), False, str(exc))


def run_gallery(outdir, *, progress: bool = True, only=None) -> list[GalleryRow]:
    """Build, check and export every entry (or the named ones); one row each."""
    items = entries()
    if only:
        unknown = sorted(set(only) - {e.name for e in items})
        if unknown:
            raise SurfmodError(f"only: unknown entities {', '.join(unknown)}")
        items = [e for e in items if e.name in only]
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    return [run_entry(e, out) for e in tqdm(items, desc="gallery", unit="entity", disable=not progress)]


def format_table(rows: list[GalleryRow]) -> str:
    """Plain-text table, columns as wide as their longest entry (nothing is cut)."""
    we = max([len("entity"), *(len(r.entity) for r in rows)])
    wc = max([len("OCCT construct"), *(len(r.construct) for r in rows)])
    head = f"{'entity':<{we}} {'OCCT construct':<{wc}} {'mode':<10} {'max dev':>10}  pass"
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.entity:<{we}} {r.construct:<{wc}} {r.mode:<10} {r.max_deviation:>10.2e}  {'yes' if r.passed else 'NO'}"
            + (f"  ({r.note})" if r.note else "")
        )
    return "\n".join(lines)
