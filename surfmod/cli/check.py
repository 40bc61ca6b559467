"""``surfmod check PATH...``: read every face of STEP files back and cross-check it."""

from __future__ import annotations

from pathlib import Path

from ..errors import SurfmodError


def register(sub) -> None:
    p = sub.add_parser("check", help="cross-check every face of STEP files (or folders of them) against OCCT")
    p.add_argument("paths", nargs="+", help="STEP files or folders")
    p.add_argument("--samples", type=int, default=24, help="samples per parameter direction (default 24)")
    p.add_argument("--jobs", type=int, default=-1, help="worker processes (default: all cores)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def step_files(paths) -> list[Path]:
    out = []
    for raw in paths:
        p = Path(raw)
        if p.is_dir():
            out.extend(sorted(q for q in p.rglob("*") if q.suffix.lower() in (".step", ".stp")))
        elif p.exists():
            out.append(p)
        else:
            raise SurfmodError(f"paths: {p} does not exist")
    if not out:
        raise SurfmodError("paths: no STEP files found")
    return out


def check_file(path: Path, samples: int) -> list[tuple]:
    """``[(file, face index, surface type, max deviation, passed, note), ...]``."""
    from ..construct.from_face import from_face
    from ..check import crosscheck
    from ..io.step import import_step
    from ..occ.geom import surface_type
    from ..occ.topo import face_surface, faces_of

    try:
        shape = import_step(path)
    except SurfmodError as exc:
        return [(str(path), -1, "-", float("nan"), False, str(exc))]
    rows = []
    for i, face in enumerate(faces_of(shape)):
        try:
            kind = surface_type(face_surface(face)[0])
            r = crosscheck(from_face(face), samples=samples)
            rows.append((str(path), i, kind, r.max_deviation, r.passed, ""))
        except SurfmodError as exc:
            rows.append((str(path), i, locals().get("kind", "-"), float("nan"), False, str(exc)))
    return rows


def run(args) -> int:
    from joblib import Parallel, delayed
    from tqdm import tqdm

    files = step_files(args.paths)
    jobs = args.jobs if len(files) > 1 else 1
    results = Parallel(n_jobs=jobs, return_as="generator")(delayed(check_file)(f, args.samples) for f in files)
    rows = [row for chunk in tqdm(results, total=len(files), desc="check", unit="file", disable=args.no_progress) for row in chunk]
    print(f"{'file':<40} {'face':>4}  {'surface type':<34} {'max dev':>10}  pass")
    for f, i, kind, dev, ok, note in rows:
        print(f"{Path(f).name:<40.40} {i:>4}  {kind:<34.34} {dev:>10.2e}  {'yes' if ok else 'NO'}" + (f"  ({note})" if note else ""))
    bad = sum(1 for r in rows if not r[4])
    print(f"\n{len(rows) - bad} of {len(rows)} faces passed")
    return 1 if bad else 0
