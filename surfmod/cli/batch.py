"""Running one per-file job over folders of STEP files: locally with joblib, or on a Dask
distributed cluster (``--scheduler ADDRESS``), results streamed as a table or a CSV file.

A job is a plain module-level function ``job(path, **options) -> list of row tuples``;
it must catch its own per-file errors and report them as rows, so one bad file never
stops a run of thousands.  Memory per worker stays bounded because a worker holds one
file at a time and only rows travel back.
"""

from __future__ import annotations

import csv
import io
import os
import sys
from pathlib import Path

from joblib import Parallel, delayed
from tqdm import tqdm

from ..errors import SurfmodError
from ..atomic import atomic_path, target_path
from ..io.step import import_step
from ..io.stl import export_stl

STEP_SUFFIXES = (".step", ".stp")


def step_files(paths) -> list[Path]:
    """STEP files named by ``paths``: files as given, folders searched recursively for
    ``.step``/``.stp`` in any letter case, sorted.  A missing path or nothing found
    raises ``SurfmodError``.

    >>> import tempfile, pathlib
    >>> d = pathlib.Path(tempfile.mkdtemp()); (d / "sub").mkdir(); (d / "sub" / "A.STP").write_text("x")
    1
    >>> [p.name for p in step_files([d])]
    ['A.STP']
    """
    out = []
    for raw in paths:
        p = Path(os.fspath(raw))
        if p.is_dir():
            found = sorted(q for q in p.rglob("*") if q.is_file() and q.suffix.lower() in STEP_SUFFIXES)
            if not found:
                raise SurfmodError(f"paths: no STEP file (.step/.stp) in folder {p}")
            out.extend(found)
        elif p.is_file():
            out.append(p)
        else:
            raise SurfmodError(f"paths: {p} does not exist")
    if not out:
        raise SurfmodError("paths: no STEP files given")
    return out


def _local(job, files, options, jobs):
    n_jobs = jobs if len(files) > 1 else 1
    return Parallel(n_jobs=n_jobs, return_as="generator")(delayed(job)(f, **options) for f in files)


def _dask(job, files, options, address):
    try:
        from distributed import Client, as_completed
    except ImportError:  # pragma: no cover - the extra is declared in pyproject
        raise SurfmodError("scheduler: running on a cluster needs dask.distributed (pip install 'surfmod[cluster]')") from None
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError) as exc:
        raise SurfmodError(f"scheduler: cannot reach the Dask scheduler at {address} ({exc})") from None
    try:
        # pure=False: a file may change between runs; one task per file keeps memory bounded
        futures = [client.submit(job, str(f), pure=False, **options) for f in files]
        for future in as_completed(futures):
            yield future.result()
            future.release()  # rows are in hand: let the cluster forget the task
    finally:
        client.close()


def run_batch(job, files, *, options=None, scheduler=None, jobs=-1, progress=True, desc="files"):
    """Yield the row lists of ``job(path, **options)`` for every file, as they finish
    (joblib in file order locally; completion order on a Dask cluster).

    >>> rows = list(run_batch(_example_job, ["a.step", "b.step"], jobs=1, progress=False))
    >>> rows
    [[('a.step', 1)], [('b.step', 1)]]
    """
    options = options or {}
    chunks = _dask(job, files, options, scheduler) if scheduler else _local(job, files, options, jobs)
    yield from tqdm(chunks, total=len(files), desc=desc, unit="file", disable=not progress, file=sys.stderr)


def _example_job(path, **_):
    return [(str(path), 1)]


class RowSink:
    """Where rows go: printed as a fixed-width table as they arrive, or collected for a
    CSV file written atomically at the end (no partial file if the run fails).

    ``columns`` are ``(name, spec)`` pairs; ``spec`` is a format spec such as ``"<40.40"``
    or ``">10.2e"`` used for the table (the CSV holds the raw values).

    >>> sink = RowSink([("file", "<6.6"), ("dev", ">8.1e")])
    file         dev
    >>> sink.add(("a.step", 0.5))
    a.step   5.0e-01
    """

    def __init__(self, columns, csv_path=None, out=None):
        self.names = [c for c, _ in columns]
        self.specs = [spec for _, spec in columns]
        self.csv_target = target_path(csv_path, "csv", (".csv",)) if csv_path else None
        self.out = out or sys.stdout
        self.rows = []
        if self.csv_target is None:
            print("  ".join(self._cell(n, spec, header=True) for n, spec in zip(self.names, self.specs)), file=self.out)

    @staticmethod
    def _cell(value, spec, header=False):
        width = spec.lstrip("<>^").split(".")[0].rstrip("egfd")
        if header or isinstance(value, str):
            return format(str(value), f"{spec[0] if spec[0] in '<>^' else '<'}{width}.{width}" if width else "")
        return format(value, spec)

    def add(self, row) -> None:
        self.rows.append(tuple(row))
        if self.csv_target is None:
            print("  ".join(self._cell(v, spec) for v, spec in zip(row, self.specs)), file=self.out, flush=True)

    def close(self) -> None:
        """Write the CSV file (atomic) when one was asked for."""
        if self.csv_target is None:
            return
        buf = io.StringIO()
        writer = csv.writer(buf)
        writer.writerow(self.names)
        writer.writerows(self.rows)
        with atomic_path(self.csv_target) as tmp:
            Path(tmp).write_text(buf.getvalue(), encoding="utf-8")


# -- plumbing shared by the commands that take many files ---------------------------------------
def add_batch_arguments(parser) -> None:
    """``--csv``, ``--scheduler`` and ``--jobs`` for a command taking ``PATH...``."""
    parser.add_argument("--jobs", type=int, default=-1, help="local worker processes (default: all cores)")
    parser.add_argument("--scheduler", help="run on the Dask distributed scheduler at this address (tcp://host:8786)")
    parser.add_argument("--csv", help="write one row per file to this CSV file instead of printing the table")


MESH_COLUMNS = [("file", "<36.36"), ("triangles", ">10d"), ("watertight", "<10.10"), ("max dev", ">10.2e"),
                ("stl", "<")]


def mesh_file(path, tolerance: float, ascii: bool = False, out_dir=None, strict: bool = False) -> list[tuple]:
    """Mesh one STEP file to an STL beside it (or in ``out_dir``) with the per-file mesh
    function of ``surfmod mesh``; ``[(file, triangles, watertight, max deviation, stl or
    error)]``."""
    p = Path(path)
    out = (Path(out_dir) / p.with_suffix(".stl").name) if out_dir else p.with_suffix(".stl")
    try:
        mesh = export_stl(import_step(p), out, tolerance=tolerance, ascii=ascii, strict=strict, progress=False)
    except SurfmodError as exc:
        return [(str(p), 0, "-", float("nan"), f"error: {' '.join(str(exc).split())}")]
    dev = mesh.info.get("max_deviation")
    return [(str(p), len(mesh.faces), "yes" if mesh.to_trimesh().is_watertight else "NO",
             float("nan") if dev is None else float(dev), str(out))]


def run_mesh(args) -> int:
    """``surfmod mesh PATH...`` over files and folders: one row per file."""
    files = step_files(args.step)
    out_dir = None
    if args.out:
        out_dir = Path(args.out)
        if not out_dir.is_dir():
            raise SurfmodError(f"out: with several files or folders --out must be an existing folder, got {out_dir}")
    sink = RowSink(MESH_COLUMNS, args.csv)
    bad = 0
    options = {"tolerance": args.tolerance, "ascii": args.ascii, "out_dir": None if out_dir is None else str(out_dir),
               "strict": bool(getattr(args, "strict", False))}
    for chunk in run_batch(mesh_file, files, options=options, scheduler=args.scheduler, jobs=args.jobs,
                           progress=not getattr(args, "no_progress", False), desc="mesh"):
        for row in chunk:
            sink.add((Path(row[0]).name if not args.csv else row[0], *row[1:]))
            bad += row[4].startswith("error") or row[2] != "yes"
    sink.close()
    print(f"{len(files) - bad} of {len(files)} file(s) meshed watertight" + (f"; rows in {args.csv}" if args.csv else ""))
    return 1 if bad else 0


def is_batch(args) -> bool:
    """True when ``surfmod mesh`` was given more than one file, a folder, ``--csv`` or ``--scheduler``."""
    paths = args.step if isinstance(args.step, list) else [args.step]
    return len(paths) > 1 or any(Path(p).is_dir() for p in paths) or bool(args.csv) or bool(args.scheduler)
