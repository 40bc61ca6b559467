"""Make ``docs/guide/job_view.png``: the job view (``surfmod machine --html``) of a block
with a pocket and a boss, roughed with a flat end mill and finished with a ball that
cannot reach the pocket's inner corners nor the foot of its walls, as headless Chromium
draws it.

    python docs/job_view_picture.py

The page is written by :func:`surfmod.cam.job_view.write_html` into a temporary folder and
rendered by the same code as the tests' (``tests/chromium.py``); the screenshot is kept
with a 128-colour palette, so the committed picture stays small.  Needs Debian's
``chromium``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import build123d as bd
from PIL import Image

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))  # the tests' Chromium helper

import chromium  # noqa: E402

import surfmod as sm  # noqa: E402
from surfmod.cam.job_view import write_html  # noqa: E402

TARGET = ROOT / "docs" / "guide" / "job_view.png"
SIZE = (1000, 720)


def main() -> Path:
    part = bd.Box(60, 40, 15) - bd.Pos(8, 0, 4) * bd.Box(30, 24, 8)
    part += bd.Pos(-20, 0, 10) * bd.Cylinder(6, 5)
    job = sm.machine(part, 2.0, [sm.Rough(sm.Tool("flat", 3.0, flute_length=25), stepdown=3.0, allowance=0.4),
                                 sm.Finish(sm.Tool("ball", 2.0, flute_length=25), scallop=0.05)])
    with tempfile.TemporaryDirectory() as tmp:
        page, shot = Path(tmp) / "job.html", Path(tmp) / "job.png"
        write_html(job, page)
        errors = chromium.screenshot(page, shot, SIZE)
        if errors:
            raise SystemExit(f"the page's scripts failed: {errors}")
        with Image.open(shot) as im:
            im.convert("RGB").quantize(colors=128).save(TARGET, optimize=True)
    return TARGET


if __name__ == "__main__":
    print(f"wrote {main()}")
