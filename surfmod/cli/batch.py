"""Running one per-file job over folders of STEP files: locally with joblib, or on a Dask
distributed cluster (``--scheduler ADDRESS``), results streamed as a table or a CSV file.

A job is a plain module-level function ``job(path, **options) -> list of row tuples``; it
catches its own per-file errors and reports them as rows, so one bad file never stops a
run, and only rows travel back, so a worker's memory stays bounded.
See :doc:`/cli` (section "Folders of many files").
"""

from __future__ import annotations

import csv
import functools
import io
import os
import sys
import threading
import warnings
from pathlib import Path

from tqdm import tqdm

from .. import child
from ..errors import RoundTripWarning, SurfmodError
from ..atomic import target_path
from ..io.stl import export_stl
from ..inputs import read_step_file

STEP_SUFFIXES = (".step", ".stp")
#: default budget of one file's task on a cluster: seconds, and GiB resident
TASK_SECONDS = 1800.0
TASK_MEMORY_GIB = 8.0


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


def _watched(job, client_pid, path, options):
    """``job(path, **options)``; in a local worker process, which then ends as soon as its
    client (the process that started the run) is gone (:func:`surfmod.child.die_with`),
    or in the client itself (a run of one job stays there)."""
    if os.getpid() != client_pid:
        child.die_with(client_pid)
    return job(path, **options)


def _local(job, files, options, jobs):
    from joblib import Parallel, delayed  # 0.15 s: a folder run's, not a single file's

    n_jobs = jobs if len(files) > 1 else 1
    # rows as each file completes, not in file order: a slow file holds back nobody's rows
    return Parallel(n_jobs=n_jobs, return_as="generator_unordered")(
        delayed(_watched)(job, os.getpid(), f, options) for f in files)


def _dask(job, files, options, address, failed_row, seconds, memory):
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
        futures = {client.submit(budgeted, job, str(f), options, seconds, memory, failed_row, pure=False): f
                   for f in files}
        for future in as_completed(futures):
            try:
                yield future.result()
            except Exception as exc:  # noqa: BLE001 - KilledWorker, a lost connection: the file, not the run
                yield [failed_row(str(futures[future]), f"skipped: {type(exc).__name__}: {' '.join(str(exc).split())}")]
            future.release()  # rows are in hand: let the cluster forget the task
    finally:
        client.close()


_servers = threading.local()


def budgeted(job, path, options, seconds, memory, failed_row):
    """``job(path, **options)`` in a child process of this (worker) thread, within
    ``seconds`` and ``memory`` bytes; over budget (or dead), the file's one row from
    ``failed_row(path, message)`` naming the budget.  The child serves the thread's
    tasks one after another (:class:`surfmod.child.Server`): its start is paid once.

    >>> budgeted(_example_job, "a.step", {}, 60.0, None, lambda p, m: [(p, m)])
    [('a.step', 1)]
    """
    server = getattr(_servers, "server", None) or child.Server()
    _servers.server = server
    try:
        return server.call(functools.partial(job, **options), (path,), seconds, f"the task of {path}", memory)
    except child.ChildFailure as exc:
        return [failed_row(path, f"skipped: {exc}")]


def run_batch(job, files, *, options=None, scheduler=None, jobs=-1, progress=True, desc="files", failed_row=None,
              task_seconds=TASK_SECONDS, task_memory=TASK_MEMORY_GIB * 2**30):
    """Yield the row lists of ``job(path, **options)`` for every file, as they finish
    (completion order).  On a Dask cluster each task runs within ``task_seconds`` and
    ``task_memory`` bytes; a file over budget or whose task killed its workers gives the
    one row ``failed_row(path, message)``.

    >>> rows = sorted(run_batch(_example_job, ["a.step", "b.step"], jobs=1, progress=False))
    >>> rows
    [[('a.step', 1)], [('b.step', 1)]]
    """
    options = options or {}
    failed_row = failed_row or (lambda path, message: (path, message))
    if scheduler:
        chunks = _dask(job, files, options, scheduler, failed_row, task_seconds, task_memory)
    else:
        chunks = _local(job, files, options, jobs)
    yield from tqdm(chunks, total=len(files), desc=desc, unit="file", disable=not progress, file=sys.stderr)


def _example_job(path, **_):
    return [(str(path), 1)]


class RowSink:
    """Where rows go: printed as a fixed-width table as they arrive, or to a CSV file,
    each file's rows in one write when :meth:`flush` is called (after each file), so a
    run that stops midway keeps every row of every file it finished.  The CSV file is
    created with the first rows: a run that fails before any file finishes writes none.

    ``columns`` are ``(name, spec)`` pairs; ``spec`` is a format spec such as ``"<40.40"``
    or ``">10.2e"`` used for the table (the CSV holds the raw values).  With ``resume``
    an existing CSV file of the same columns is kept (a last line cut off by a crash is
    dropped) and appended to; its rows are in :attr:`previous`.

    >>> sink = RowSink([("file", "<6.6"), ("dev", ">8.1e")])
    file         dev
    >>> sink.add(("a.step", 0.5))
    a.step   5.0e-01
    """

    def __init__(self, columns, csv_path=None, out=None, resume=False):
        self.names = [c for c, _ in columns]
        self.specs = [spec for _, spec in columns]
        self.csv_target = target_path(csv_path, "csv", (".csv",)) if csv_path else None
        self.out = out or sys.stdout
        self.pending, self.previous, self.stream = [], [], None
        if resume and self.csv_target is None:
            raise SurfmodError("resume: needs --csv, the file whose rows it keeps")
        if resume and self.csv_target.exists():
            self.previous = self._kept_rows()
            self.stream = self.csv_target.open("a", newline="", encoding="utf-8")
        if self.csv_target is None:
            print("  ".join(self._cell(n, spec, header=True) for n, spec in zip(self.names, self.specs)), file=self.out)

    def _kept_rows(self) -> list:
        """The rows of the existing CSV file, after cutting off a last line left
        unfinished (no newline) by a run that died while writing it."""
        raw = self.csv_target.read_bytes()
        if raw and not raw.endswith(b"\n"):
            raw = raw[: raw.rfind(b"\n") + 1]
            with self.csv_target.open("r+b") as f:
                f.truncate(len(raw))
        rows = list(csv.reader(io.StringIO(raw.decode("utf-8"), newline="")))
        if rows and rows[0] != self.names:
            raise SurfmodError(f"csv: {self.csv_target} has the columns {', '.join(rows[0])}, not "
                               f"{', '.join(self.names)}: not a file of this command to resume")
        return rows[1:]

    def done_files(self) -> set:
        """Absolute paths of the files whose rows the resumed CSV file holds."""
        return {os.path.abspath(r[0]) for r in self.previous if r}

    @staticmethod
    def _cell(value, spec, header=False):
        width = spec.lstrip("<>^").split(".")[0].rstrip("egfd")
        if header or isinstance(value, str):
            return format(str(value), f"{spec[0] if spec[0] in '<>^' else '<'}{width}.{width}" if width else "")
        return format(value, spec)

    def add(self, row) -> None:
        if self.csv_target is None:
            print("  ".join(self._cell(v, spec) for v, spec in zip(row, self.specs)), file=self.out, flush=True)
        else:
            self.pending.append(tuple(row))

    def flush(self) -> None:
        """Write the rows added since the last flush to the CSV file, in one write."""
        if self.csv_target is None or not self.pending:
            return
        buf = io.StringIO()
        writer = csv.writer(buf)
        if self.stream is None:
            self.stream = self.csv_target.open("w", newline="", encoding="utf-8")
            writer.writerow(self.names)
        writer.writerows(self.pending)
        self.pending = []
        self.stream.write(buf.getvalue())
        self.stream.flush()

    def close(self) -> None:
        """Write what is left and close the CSV file."""
        self.flush()
        if self.stream is not None:
            self.stream.close()
            self.stream = None


# -- plumbing shared by the commands that take many files ---------------------------------------
def add_batch_arguments(parser, rows: str = "one row per file") -> None:
    """``--csv``, ``--resume``, ``--scheduler``, ``--jobs`` and the task budgets for a
    command taking ``PATH...``."""
    parser.add_argument("--jobs", type=int, default=-1, help="local worker processes (default: all cores)")
    parser.add_argument("--scheduler", help="run on the Dask distributed scheduler at this address (tcp://host:8786)")
    parser.add_argument("--csv", help=f"write {rows} to this CSV file, each file's rows as it completes, instead of "
                                      "printing the table")
    parser.add_argument("--resume", action="store_true",
                        help="keep the rows already in --csv and skip their files (after a crash or Ctrl-C)")
    parser.add_argument("--task-seconds", type=float, default=TASK_SECONDS,
                        help="with --scheduler: a file's task is skipped after this many seconds "
                             f"(default {TASK_SECONDS:g})")
    parser.add_argument("--task-memory", type=float, default=TASK_MEMORY_GIB,
                        help=f"with --scheduler: a file's task is skipped above this many GiB resident (default "
                             f"{TASK_MEMORY_GIB:g})")


def batch_run(args, job, options, columns, desc, failed_row, record=tuple):
    """Run ``job`` over ``args.files`` for a command: each row as ``record(row)`` makes
    it to the CSV file (flushed after each file) or the table (file names only there),
    ``--resume`` honoured (``args.skipped`` says how many files it skipped).  Yields
    ``(recorded row, fresh)`` for every row, the resumed CSV's rows first (``fresh``
    False, their cells as read), then this run's."""
    files = args.files
    for name, limit in (("task_seconds", args.task_seconds), ("task_memory", args.task_memory)):
        if not limit > 0:
            raise SurfmodError(f"{name.replace('_', '-')}: must be > 0, got {limit}")
    sink = RowSink(columns, args.csv, resume=args.resume)
    done = sink.done_files()
    todo = [f for f in files if os.path.abspath(f) not in done]
    args.skipped = len(files) - len(todo)
    for row in sink.previous:
        yield row, False
    try:
        for chunk in run_batch(job, todo, options=options, scheduler=args.scheduler, jobs=args.jobs,
                               progress=not getattr(args, "no_progress", False), desc=desc, failed_row=failed_row,
                               task_seconds=args.task_seconds, task_memory=args.task_memory * 2**30):
            for row in chunk:
                row = record(row)
                sink.add(row if args.csv else (Path(row[0]).name, *row[1:]))
                yield row, True
            sink.flush()
    finally:
        sink.close()


MESH_COLUMNS = [("file", "<36.36"), ("exit", ">4d"), ("triangles", ">10d"), ("watertight", "<10.10"),
                ("closed", "<6.6"), ("manifold", "<8.8"), ("outward", "<7.7"), ("repairs", ">7d"),
                ("max dev", ">10.2e"), ("stl", "<"), ("verdict", "<")]
#: exit status of one file whose STL was written but breaks its promise (as ``surfmod mesh FILE``)
EXIT_BROKEN = 3


def mesh_failed(path, message) -> tuple:
    """The one row of a file ``surfmod mesh`` could not mesh (exit 1, nothing judged)."""
    return (str(path), 1, 0, "-", "-", "-", "-", 0, float("nan"), "-", f"error: {message}")


def stl_verdict(mesh) -> tuple:
    """``(exit, closed, manifold, outward, repairs, verdict)`` of the STL ``mesh`` as
    :func:`surfmod.export_stl` read it back and judged it: ``closed``, ``manifold`` and
    ``outward`` ``"yes"``/``"NO"`` over every solid that promised to close, ``repairs``
    the edges and facets admesh would mend (open, non-manifold and inconsistently wound
    edges, degenerate facets) plus one per solid inside out, and the broken promises in
    words (empty when kept); exit 3 on any, as the single-file command.

    >>> from surfmod.meshing.closure import Closure
    >>> class M: info = {"stl_problems": ["solid 2: 3 open edge(s)"], "stl_verdicts": [("solid 2", Closure(3, 0, 0, 0, 1.0, (4,)))]}
    >>> stl_verdict(M())
    (3, 'NO', 'yes', 'yes', 3, 'solid 2: 3 open edge(s)')
    """
    verdicts = [v for _, v in mesh.info.get("stl_verdicts", [])]
    problems = mesh.info.get("stl_problems", [])

    def said(bad) -> str:
        return "NO" if any(bad(v) for v in verdicts) else "yes"

    repairs = sum(v.open + v.non_manifold + v.inconsistent + v.degenerate + (v.volume <= 0) for v in verdicts)
    return (EXIT_BROKEN if problems else 0, said(lambda v: v.open), said(lambda v: v.non_manifold),
            said(lambda v: v.inconsistent or v.volume <= 0), int(repairs), "; ".join(problems))


def mesh_file(path, tolerance: float, ascii: bool = False, out_dir=None, strict: bool = False) -> list[tuple]:
    """Mesh one STEP file to an STL beside it (or in ``out_dir``) with the per-file mesh
    function of ``surfmod mesh``; ``[(file, exit, triangles, watertight, closed, manifold,
    outward, repairs, max deviation, stl, verdict)]``: the STL read back and judged
    (:func:`stl_verdict`), exit 3 when it breaks a promise, 1 with the error when the file
    cannot be meshed, as ``surfmod mesh FILE`` would exit."""
    p = Path(path)
    out = (Path(out_dir) / p.with_suffix(".stl").name) if out_dir else p.with_suffix(".stl")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RoundTripWarning)  # the row says it, in its verdict
            mesh = export_stl(read_step_file(p, "step"), out, tolerance=tolerance, ascii=ascii, strict=strict, progress=False)
    except SurfmodError as exc:
        return [mesh_failed(p, " ".join(str(exc).split()))]
    code, closed, manifold, outward, repairs, verdict = stl_verdict(mesh)
    dev = mesh.info.get("max_deviation")
    return [(str(p), code, len(mesh.faces), "yes" if mesh.edge_use()[0] else "NO", closed, manifold,
             outward, repairs, float("nan") if dev is None else float(dev), str(out), verdict)]


def run_mesh(args) -> int:
    """``surfmod mesh PATH...`` over files and folders: one row per file; the exit status
    is the worst file's (3, an STL that breaks its promise, over 1, a file not meshed)."""
    args.files = step_files(args.step)
    out_dir = None
    if args.out:
        out_dir = Path(args.out)
        if not out_dir.is_dir():
            raise SurfmodError(f"out: with several files or folders --out must be an existing folder, got {out_dir}")
    codes = []
    options = {"tolerance": args.tolerance, "ascii": args.ascii, "out_dir": None if out_dir is None else str(out_dir),
               "strict": bool(getattr(args, "strict", False))}
    for row, _ in batch_run(args, mesh_file, options, MESH_COLUMNS, "mesh", mesh_failed):
        codes.append(int(row[1]))
    resumed = f" ({args.skipped} already in {args.csv})" if args.skipped else ""
    broken, failed = codes.count(EXIT_BROKEN), sum(c not in (0, EXIT_BROKEN) for c in codes)
    print(f"{codes.count(0)} of {len(codes)} file(s) meshed, every STL read back as promised{resumed}"
          + (f"; {broken} broke a promise (exit 3)" if broken else "")
          + (f"; {failed} not meshed (exit 1)" if failed else "")
          + (f"; rows in {args.csv}" if args.csv else ""))
    return EXIT_BROKEN if broken else 1 if failed else 0


def is_batch(args) -> bool:
    """True when ``surfmod mesh`` was given more than one file, a folder, ``--csv`` or ``--scheduler``."""
    paths = args.step if isinstance(args.step, list) else [args.step]
    return len(paths) > 1 or any(Path(p).is_dir() for p in paths) or bool(args.csv) or bool(args.scheduler)
