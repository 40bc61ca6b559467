"""Child process of the STEP fuzz tests: reads one JSON case per line on stdin, runs it,
answers one JSON line on stdout.  A crash of this process is seen by the parent test as
a failure of the case it was running, never as a dead test run.

Cases: ``{"kind": "import", "path": P, "timeout": T}`` runs ``surfmod.import_step`` and
``{"kind": "cli", "argv": [...]}`` runs ``surfmod.cli.main`` with stdout/stderr captured.
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
import traceback


def _import(case):
    import numpy as np

    import surfmod as sm

    try:
        shape = sm.import_step(case["path"], timeout=case["timeout"])
    except sm.SurfmodError as exc:
        return {"outcome": "error", "type": type(exc).__name__, "message": str(exc)}
    except Exception as exc:  # noqa: BLE001 - what the test is looking for: must not happen
        return {"outcome": "raw", "type": type(exc).__name__, "message": traceback.format_exc()}
    box = shape.bounding_box()
    corners = np.array([tuple(box.min), tuple(box.max)])
    return {"outcome": "ok", "faces": len(shape.faces()), "finite": bool(np.isfinite(corners).all())}


def _cli(case):
    from surfmod.cli import main

    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(case["argv"])
    except SystemExit as exc:  # argparse
        code = exc.code
    except Exception:  # noqa: BLE001 - a raw exception escaping the command line
        return {"outcome": "raw", "code": None, "stderr": err.getvalue() + traceback.format_exc(), "stdout": ""}
    return {"outcome": "done", "code": code, "stderr": err.getvalue(), "stdout": out.getvalue()[-2000:]}


def main() -> None:
    import os

    # replies go to a private copy of stdout: OCCT writes to file descriptor 1 directly
    reply = os.fdopen(os.dup(1), "w")
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    for line in sys.stdin:
        case = json.loads(line)
        result = _import(case) if case["kind"] == "import" else _cli(case)
        reply.write(json.dumps(result) + "\n")
        reply.flush()


if __name__ == "__main__":
    main()
