"""``surfmod check PATH...``: read every face of STEP files (or folders of them) back and
cross-check it against OCCT; one row per face, streamed, or ``--csv FILE``.

Exit 1 when a face fails its cross-check or a file cannot be read; 3 (partial) when every
face checked passes but some could not be checked (surfmod could not read them back or
OCCT could not sample them): those are named, with their count."""

from __future__ import annotations

from pathlib import Path

from ..errors import SurfmodError
from ..io.step_iges import import_step
from ..readback import from_face
from ..readback.strays import edge_strays
from ..occt_crosscheck import crosscheck_many
from . import EXIT_PARTIAL
from .batch import add_batch_arguments, batch_run, step_files

COLUMNS = [("file", "<36.36"), ("face", ">5d"), ("surface type", "<30.30"), ("max dev", ">10.2e"),
           ("pass", "<4.4"), ("note", "<")]


def register(sub) -> None:
    p = sub.add_parser("check", help="cross-check every face of STEP files (or folders of them) against OCCT")
    p.add_argument("paths", nargs="+", help="STEP files or folders (searched recursively for .step/.stp)")
    p.add_argument("--samples", type=int, default=24, help="samples per parameter direction (default 24)")
    add_batch_arguments(p, "the rows (one per face)")
    p.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.set_defaults(run=run)


def _note(result) -> str:
    """What failed, with the measured figure and its limit; what was not judged."""
    details = result.details
    parts = [f"{k} {v:.2e} > {lim:.1e}" for k, (v, lim) in details.get("failed", {}).items()]
    if not result.passed and not parts and "tolerance" in details:
        parts.append(f"deviation {result.max_deviation:.2e} > {details['tolerance']:.1e}")
    if details.get("curvature_settled"):
        parts.append(details["curvature_settled"])
    if details.get("knot_jump_points"):
        parts.append(f"{details['knot_jump_points']} samples on C1/C0 knot lines: derivatives the surface has not "
                     "got there skipped")
    if details.get("short_span_points"):
        parts.append(f"{details['short_span_points']} samples on round-off-wide knot spans: position only")
    return "; ".join(parts)


def check_file(path, samples: int = 24) -> list[tuple]:
    """``[(file, face index, surface type, max deviation, passed, note), ...]`` for one
    STEP file; an unreadable file is one row with face index -1.  ``passed`` is None for
    a face that could not be checked (its note starts with "not checked:" and the reason).

    Each face is read back once (:func:`surfmod.from_face`) and cross-checked with
    ``sampling="sufficient"``: at most ``samples`` values per direction (plus knots), fewer
    where fewer already prove agreement with OCCT over the whole face (elementary
    surfaces, B-splines with few spans; see
    :func:`surfmod.occt_crosscheck.sufficient_parameters`).

    >>> import surfmod as sm, build123d as bd, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "box.step")
    >>> sm.export_step(bd.Box(1, 2, 3), path)
    >>> rows = check_file(path, 8)
    >>> len(rows), all(r[4] for r in rows), rows[0][2]
    (6, True, 'Geom_Plane')
    """
    from ..occ.geom import surface_type
    from ..occ.topo import faces_of

    name = str(path)
    try:
        shape = import_step(path)
    except SurfmodError as exc:
        return [(name, -1, "-", float("nan"), False, str(exc))]
    rows, reads = {}, {}
    for i, face in enumerate(faces_of(shape)):
        try:
            reads[i] = from_face(face)
        except SurfmodError as exc:
            rows[i] = (name, i, _kind_of(face), float("nan"), None, f"not checked: {exc}")
    # one batch: OCCT sampled face by face, the comparison vectorized over all faces
    results = crosscheck_many(list(reads.values()), samples=samples, sampling="sufficient")
    for (i, read), r in zip(reads.items(), results):
        kind = surface_type(read.geom())
        if isinstance(r, SurfmodError):
            rows[i] = (name, i, kind, float("nan"), None, f"not checked: {r}")
        else:
            rows[i] = (name, i, kind, r.max_deviation, r.passed, _note(r))
    for i, note in _stray_notes(shape).items():
        if i in rows:
            f, j, kind, dev, ok, old = rows[i]
            rows[i] = (f, j, kind, dev, ok, "; ".join(x for x in (old, note) if x))
    return [rows[i] for i in sorted(rows)]


def _stray_notes(shape) -> dict:
    """Per face index a note on its edges whose p-curves stray from the 3-D curve (or
    from each other) beyond the edge's own tolerance: there the model is ambiguous."""
    try:
        strays = [e for e in edge_strays(shape, samples=9) if e.ambiguous]
    except SurfmodError:
        return {}
    per_face: dict = {}
    for e in strays:
        for i in e.faces:
            per_face.setdefault(i, []).append(e)
    notes = {}
    for i, edges in per_face.items():
        worst = max(edges, key=lambda e: max(e.stray, e.gap) / max(e.tolerance, 1e-300))
        notes[i] = (f"ambiguous: {len(edges)} edge(s) whose p-curves stray beyond their tolerance, worst edge "
                    f"{worst.edge}: {max(worst.stray, worst.gap):.2e} > tol {worst.tolerance:.1e}")
    return notes


def _kind_of(face) -> str:
    """The OCCT surface type of a face that could not be read back, or "-"."""
    from ..occ.geom import surface_type
    from ..occ.topo import face_surface

    try:
        return surface_type(face_surface(face)[0])
    except SurfmodError:
        return "-"


def check_failed(path, message) -> tuple:
    """The one row of a file whose task was skipped (over its budget, or it killed its
    workers): face index -1, not checked (exit 3, partial)."""
    return (str(path), -1, "-", float("nan"), None, message)


def _recorded(row) -> tuple:
    f, i, kind, dev, ok, note = row
    return (f, i, kind, dev, "skip" if ok is None else "yes" if ok else "NO", note)


def run(args) -> int:
    args.files = files = step_files(args.paths)
    faces = bad = 0
    unchecked = []
    for (f, i, _, _, ok, _), _fresh in batch_run(args, check_file, {"samples": args.samples}, COLUMNS, "check",
                                                 check_failed, _recorded):
        faces += 1
        bad += ok == "NO"
        if ok == "skip":
            unchecked.append(f"{Path(f).name} face {i}")
    passed = faces - bad - len(unchecked)
    resumed = f" ({args.skipped} already in {args.csv})" if args.skipped else ""
    print(f"{passed} of {faces} faces passed in {len(files)} file(s){resumed}"
          + (f"; rows in {args.csv}" if args.csv else ""))
    if unchecked:
        shown = ", ".join(unchecked[:20]) + (f" and {len(unchecked) - 20} more" if len(unchecked) > 20 else "")
        print(f"partial: {len(unchecked)} of {faces} face(s) could not be checked: {shown}")
    return 1 if bad else EXIT_PARTIAL if unchecked else 0
