"""Folders of many files: ``surfmod check DIR`` on a local Dask cluster of 2 workers
(``--scheduler``) against the same run on 2 local processes (``--jobs 2``), in files per
minute, with the peak memory of each worker.

The folder holds ``N`` files, links to the corpus files (tests/data/step) taken in turn
(``00000_axom_boxed_sphere.step``, ...); each run checks it into a CSV (``--csv``, as a
long run would) in a fresh Python process, so every worker starts cold and its peak is
its own.  A run of ``2N`` files follows each run of ``N``: a file's shapes are freed after
its task when the peak does not grow with the number of files.

* **files/min**: files over the command's wall time, the cluster already up (as on an
  existing cluster; its start is the ``start`` column) and the workers cold.
* **peak worker MiB**: per worker, the peak resident memory (Linux ``VmHWM``) of each
  process of its tree, summed, then the largest over the workers.  On the cluster a
  worker's tree is its Dask worker process, the child that runs its tasks
  (:class:`surfmod.child.Server`) and that child's STEP reader process; with ``--jobs``
  it is the loky worker process and its STEP reader.  Each process's peak is read once
  the run has ended (the processes are still up), so no peak between two looks is missed.
* **end MiB**: the same trees' resident memory at the end: what the workers still hold.

``python -m benchmarks folders``                   N = 50 (then 100): a few minutes on 2 cores
``python -m benchmarks folders --files 10000``     the ten-thousand-file run (then 20,000)
``python -m benchmarks folders --files 500 --no-double``   one size only
``python -m benchmarks folders --files 10000 --no-double --modes dask``   the cluster alone
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from .tables import Table, note

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"
#: files in the default run (the doubled run has twice as many): about 4 minutes in all on
#: 2 loaded cores (load average 8), 100 files taking 85 s each way
FILES = 50
WORKERS = 2
MIB = 2**20


def corpus_files() -> list[Path]:
    return sorted(p for p in CORPUS.glob("*") if p.suffix.lower() in (".step", ".stp"))


def build_folder(folder: Path, count: int) -> list[Path]:
    """``count`` links in ``folder`` to the corpus files taken in turn (symbolic links:
    the files are read where they are; names keep the corpus name after a serial number)."""
    corpus = corpus_files()
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for i in range(count):
        source = corpus[i % len(corpus)]
        link = folder / f"{i:05d}_{source.name}"
        link.symlink_to(source)
        out.append(link)
    return out


def _status(pid: int) -> dict:
    """``VmHWM`` (peak) and ``VmRSS`` (now) of process ``pid`` in bytes, from ``/proc``."""
    found = {}
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key in ("VmHWM", "VmRSS"):
                    found[key] = int(value.split()[0]) * 1024
    except OSError:  # gone since it was listed
        pass
    return found


def tree_memory(pid: int | None = None) -> dict:
    """The peak and current resident bytes of process ``pid`` (default: this one) and of
    every process below it, summed, with how many processes that is.  Run on each Dask
    worker by ``client.run``."""
    import psutil

    pid = os.getpid() if pid is None else pid
    procs = [pid] + [p.pid for p in psutil.Process(pid).children(recursive=True)]
    figures = [_status(p) for p in procs]
    return {"peak": sum(f.get("VmHWM", 0) for f in figures), "now": sum(f.get("VmRSS", 0) for f in figures),
            "processes": sum(bool(f) for f in figures)}


def _one(mode: str, folder: str, rows: str) -> dict:
    """In a fresh process: one ``surfmod check`` run of ``folder`` into the CSV ``rows``,
    ``mode`` "dask" (a local cluster of :data:`WORKERS`) or "jobs"; its seconds and each
    worker tree's memory."""
    import psutil

    from surfmod.cli import main

    command = ["check", folder, "--csv", rows, "--no-progress"]
    if mode == "jobs":
        start = time.perf_counter()
        code = main([*command, "--jobs", str(WORKERS)])
        seconds = time.perf_counter() - start
        # loky's workers stay up for reuse after the run: each is a child of this process
        # (its resource tracker too: not a worker, it runs no task)
        workers = [p for p in psutil.Process().children() if "resource_tracker" not in " ".join(p.cmdline())]
        return {"code": code, "seconds": seconds, "start": 0.0, "workers": [tree_memory(p.pid) for p in workers]}
    import distributed

    t = time.perf_counter()
    with distributed.LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        client.wait_for_workers(WORKERS)
        started = time.perf_counter() - t
        start = time.perf_counter()
        code = main([*command, "--scheduler", cluster.scheduler_address])
        seconds = time.perf_counter() - start
        workers = list(client.run(tree_memory).values())
    return {"code": code, "seconds": seconds, "start": started, "workers": workers}


def _run(mode: str, folder: Path, rows: Path) -> dict:
    """:func:`_one` in a fresh process (cold workers, peaks of this run only); the CSV's
    files and rows counted."""
    env = dict(os.environ)
    for var in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS"):  # one core per worker, as every benchmark
        env.setdefault(var, "1")
    root = Path(__file__).resolve().parent.parent
    done = subprocess.run([sys.executable, "-m", "benchmarks.bench_folders", "--one", mode, str(folder), str(rows)],
                          cwd=root, env=env, capture_output=True, text=True)
    if done.returncode != 0 or not done.stdout.strip():
        raise RuntimeError(f"the {mode} run failed (exit {done.returncode}): {done.stderr.strip()[-2000:]}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    with rows.open(newline="") as f:
        table = list(csv.DictReader(f))
    result["files"] = len({r["file"] for r in table})
    result["faces"] = len(table)
    result["failed"] = sum(r["pass"] != "yes" for r in table)
    return result


def _options(argv):
    parser = argparse.ArgumentParser(prog="python -m benchmarks folders", add_help=False)
    parser.add_argument("--files", type=int, default=FILES, help=f"files in the folder (default {FILES})")
    parser.add_argument("--no-double", action="store_true", help="skip the run of twice as many files")
    parser.add_argument("--modes", default="jobs,dask", help="runs to make: jobs, dask or both (default jobs,dask)")
    opts, _ = parser.parse_known_args(argv)
    if opts.files < 1:
        raise SystemExit(f"--files: expected a positive count, got {opts.files}")
    modes = [m.strip() for m in opts.modes.split(",") if m.strip()]
    if not modes or any(m not in ("jobs", "dask") for m in modes):
        raise SystemExit(f"--modes: expected jobs, dask or jobs,dask, got {opts.modes!r}")
    return opts.files, not opts.no_double, modes


def main(argv=None) -> None:
    count, double, modes = _options(sys.argv[1:] if argv is None else argv)
    if not corpus_files():
        print(f"no corpus file at {CORPUS}")
        return
    sizes = [count, 2 * count] if double else [count]
    runs = {"jobs": f"{WORKERS} local processes (--jobs {WORKERS})",
            "dask": f"a local Dask cluster of {WORKERS} workers, one thread each (--scheduler)"}
    note(f"surfmod check DIR: {' against '.join(runs[m] for m in modes)}; the folder links the "
         f"{len(corpus_files())} corpus files in turn; rows to a CSV; each run in a fresh process (NUMBA_NUM_THREADS and OMP_NUM_THREADS 1 "
         "unless set); peak and end memory per worker tree (worker, task child, STEP reader)")
    table = Table(("run", 22, "<"), ("files", 6), ("faces", 7), ("not passed", 10), ("seconds", 8),
                  ("files/min", 9), ("start s", 7), ("peak worker MiB", 15), ("end MiB", 8), ("exit", 4))
    table.header()
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            folder = Path(tmp) / f"folder{n}"
            build_folder(folder, n)
            for mode, name in (("jobs", f"--jobs {WORKERS}"), ("dask", f"--scheduler ({WORKERS} workers)")):
                if mode not in modes:
                    continue
                r = results[mode, n] = _run(mode, folder, Path(tmp) / f"{mode}{n}.csv")
                peak = max(w["peak"] for w in r["workers"]) / MIB
                end = max(w["now"] for w in r["workers"]) / MIB
                r["peak"] = peak
                table.row(name, str(r["files"]), str(r["faces"]), str(r["failed"]), f"{r['seconds']:.1f}",
                          f"{60 * n / r['seconds']:.0f}", f"{r['start']:.1f}", f"{peak:.0f}", f"{end:.0f}",
                          str(r["code"]))
    for n in sizes if len(modes) == 2 else ():
        r_jobs, r_dask = results["jobs", n], results["dask", n]
        note(f"{n} files: the cluster checks {r_dask['seconds'] / r_jobs['seconds']:.2f}x as long as --jobs "
             f"{WORKERS} ({60 * n / r_dask['seconds']:.0f} against {60 * n / r_jobs['seconds']:.0f} files/min).")
    if double:
        growth = ", ".join(f"{name} {results[mode, 2 * count]['peak'] / results[mode, count]['peak']:.2f}x"
                           for mode, name in (("jobs", "--jobs"), ("dask", "cluster")) if mode in modes)
        note(f"Peak worker memory at {2 * count} files over the peak at {count}: {growth} (1.00x: a file's shapes "
             "are freed after its task; memory that grew with the files would show here).")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--one"]:
        print(json.dumps(_one(*sys.argv[2:5])))
    else:
        main()
