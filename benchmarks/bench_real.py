"""Real parts: every command's job on each file of tests/data/step, timed beside
OCCT's own tool for the same job, both on one core, in one process.

| job | surfmod | OCCT's tool |
|---|---|---|
| read | ``sm.import_step`` | ``STEPControl_Reader`` (ReadFile + TransferRoots) |
| check | ``surfmod check``'s per-file work (read, every face read back and cross-checked) | read + ``BRepCheck_Analyzer`` |
| mesh | ``sm.export_stl`` at 1e-3 of the bbox diagonal (BRepMesh, every face *measured*, STL written) | ``BRepMesh_IncrementalMesh`` at the same deflection, then ``StlAPI_Writer`` (the same job: an STL on disk; no measurement) |
| mass | ``sm.mass_properties`` | ``BRepGProp.VolumeProperties_s`` at eps 1e-9 |
| section | ``sm.section`` through the bbox centre, normal z | ``BRepAlgoAPI_Section`` with that plane |

Each time is the best of ``REPEATS`` runs (ours and OCCT's alternating); "x" is surfmod / OCCT (target <= 2).  A job
that raises shows its error class instead of a time.

``python -m benchmarks real``                        every job on every file
``python -m benchmarks real --only check``           only the named jobs (comma-separated)
``python -m benchmarks real --only check --files as1``  only files whose name contains a word
``python -m benchmarks real --repeats 5``            best of 5 runs (on a loaded machine)
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import surfmod as sm

from .tables import Table, captured_stdout, note

CORPUS = Path(__file__).resolve().parent.parent / "tests" / "data" / "step"
REPEATS = 2


def _best(fn, repeats: int = REPEATS):
    """Best wall time of ``fn()`` over ``repeats`` runs, or the exception's class name."""
    return _best_pair(fn, None, repeats)[0]


def _best_pair(ours, theirs, repeats: int = REPEATS):
    """Best wall times of two jobs run alternately (so both see the same machine load);
    a job that raises gives its exception's class name."""
    best = [np.inf, np.inf]
    for _ in range(repeats):
        for k, fn in enumerate((ours, theirs)):
            if fn is None or isinstance(best[k], str):
                continue
            t = time.perf_counter()
            try:
                fn()
            except Exception as exc:  # a failing job is a row entry, not the end of the table
                best[k] = type(exc).__name__
                continue
            best[k] = min(best[k], time.perf_counter() - t)
    return tuple(best)


def _occt_read(path):
    from OCP.STEPControl import STEPControl_Reader

    reader = STEPControl_Reader()
    reader.ReadFile(str(path))
    reader.TransferRoots()
    return reader.OneShape()


def _occt_jobs(path, shape, deflection, centre, out):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.BRepMesh import BRepMesh_IncrementalMesh
    from OCP.BRepTools import BRepTools
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
    from OCP.GProp import GProp_GProps
    from OCP.StlAPI import StlAPI_Writer

    def mesh():
        BRepTools.Clean_s(shape)
        BRepMesh_IncrementalMesh(shape, deflection, False, 0.5, False)
        StlAPI_Writer().Write(shape, str(out))

    def mass():
        BRepGProp.VolumeProperties_s(shape, GProp_GProps(), 1e-9)

    def section():
        BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(*centre), gp_Dir(0, 0, 1))).Shape()

    return {
        "read": lambda: _occt_read(path),
        "check": lambda: BRepCheck_Analyzer(_occt_read(path)).IsValid(),
        "mesh": mesh,
        "mass": mass,
        "section": section,
    }


def _surfmod_jobs(path, part, tolerance, centre, out):
    from surfmod.cli.check import check_file

    return {
        "read": lambda: sm.import_step(path),
        "check": lambda: check_file(path, 24),
        "mesh": lambda: sm.export_stl(part, out, tolerance),
        "mass": lambda: sm.mass_properties(part),
        "section": lambda: sm.section(part, centre, (0, 0, 1)),
    }


JOBS = ("read", "check", "mesh", "mass", "section")


def _cell(ours, theirs) -> str:
    if isinstance(ours, str):
        return ours
    if isinstance(theirs, str):
        return f"{ours:.3f} / -"
    return f"{ours:.3f} / {theirs:.3f} = {ours / theirs:.1f}x"


def _options(argv):
    """``--only`` jobs and ``--files`` name filters from the command line (after
    ``python -m benchmarks real``; other words are ignored)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks real", add_help=False)
    parser.add_argument("--only", default=",".join(JOBS), help="comma-separated jobs, e.g. check,mass")
    parser.add_argument("--files", nargs="*", default=(), help="keep files whose name contains any of these")
    parser.add_argument("--repeats", type=int, default=REPEATS, help=f"best of this many runs (default {REPEATS})")
    opts, _ = parser.parse_known_args(argv)
    jobs = tuple(j for j in JOBS if j in opts.only.split(","))
    if not jobs:
        raise SystemExit(f"--only: expected some of {', '.join(JOBS)}, got {opts.only!r}")
    if opts.repeats < 1:
        raise SystemExit(f"--repeats: expected a positive count, got {opts.repeats}")
    return jobs, tuple(opts.files), opts.repeats


def main(argv=None) -> None:
    from surfmod.meshing.figures import shape_diagonal

    jobs, words, repeats = _options(sys.argv[1:] if argv is None else argv)
    files = sorted(p for p in CORPUS.glob("*") if p.suffix.lower() in (".step", ".stp"))
    files = [p for p in files if not words or any(w in p.name for w in words)]
    if not files:
        print(f"no corpus file at {CORPUS}" + (f" matching {' '.join(words)}" if words else ""))
        return
    note("seconds: surfmod / OCCT = ratio; mesh at 1e-3 of the bbox diagonal")
    table = Table(("file", 43), *((job, 24) for job in jobs), left_first=True)
    table.header()
    complaints = {}  # file -> the distinct lines OCCT printed while its row was measured
    with tempfile.TemporaryDirectory() as tmp:
        out, occt_out = Path(tmp) / "part.stl", Path(tmp) / "occt.stl"
        for path in files:
            # OCCT's in-process reader logs on file descriptor 1 (e.g. "*** ERR
            # StepReaderData : Unresolved Reference"): kept out of the table, said below
            with captured_stdout() as printed:
                part = sm.import_step(path)
                diag = shape_diagonal(part)
                bb = part.bounding_box()
                centre = tuple(float(x) for x in (np.array(tuple(bb.min)) + np.array(tuple(bb.max))) / 2)
                ours = _surfmod_jobs(path, part, 1e-3 * diag, centre, out)
                theirs = _occt_jobs(path, _occt_read(path), 1e-3 * diag, centre, occt_out)
                cells = [_cell(*_best_pair(ours[job], theirs[job], repeats)) for job in jobs]
            if printed:
                complaints[path.name] = list(dict.fromkeys(printed))
            table.row(path.name[:43], *cells)
    for name, lines in complaints.items():
        said = "; ".join(f"`{line.strip('* ')}`" for line in lines)
        note(f"OCCT's STEP reader complained on {name} (each read, the timed ones included): {said}.")
    if not complaints:
        note("OCCT's STEP reader read every file without a complaint.")


if __name__ == "__main__":
    main()
