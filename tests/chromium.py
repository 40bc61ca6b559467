"""A page rendered by headless Chromium (Debian ``chromium``): its screenshot and what its
console said.  The tests of the job view and ``docs/job_view_picture.py`` share it.

Chromium runs with a fresh profile, no network (no host name resolves, so a page that
needs one draws nothing), no network services, software WebGL (SwiftShader:
plotly's 3-D scenes are WebGL) and a virtual time budget that lets the page's scripts
run and draw before the screenshot is taken; a wall-clock ``timeout`` only stops a hung
browser.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from pathlib import Path

#: where Debian puts it, then whatever the PATH holds
CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser")
#: console lines that say a script failed (Chromium logs every console level as INFO:CONSOLE)
CONSOLE = re.compile(r":CONSOLE[^\]]*\]\s*(.*)")
FAILED = re.compile(r"uncaught|error", re.IGNORECASE)


def find() -> str | None:
    """The Chromium executable, or None."""
    for name in CANDIDATES:
        path = shutil.which(name)
        if path:
            return path
    return None


def screenshot(page: Path, png: Path, size=(900, 700), budget_ms: int = 8000, timeout: float = 180.0) -> list[str]:
    """Render the HTML file ``page`` into ``png`` (``size`` pixels); returns the console
    lines that report an error (an uncaught exception, ``console.error``)."""
    exe = find()
    if exe is None:
        raise FileNotFoundError("chromium not found (Debian: apt-get install chromium)")
    with tempfile.TemporaryDirectory(prefix="surfmod-chromium-") as profile:
        run = subprocess.run(
            [exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-quic",
             "--no-first-run", "--disable-background-networking", "--host-resolver-rules=MAP * ~NOTFOUND", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={profile}", f"--screenshot={png}", f"--window-size={size[0]},{size[1]}",
             f"--virtual-time-budget={budget_ms}", "--enable-logging=stderr", "--v=0",
             Path(page).resolve().as_uri()],
            capture_output=True, text=True, timeout=timeout, check=False)
    if run.returncode != 0 or not Path(png).exists():
        raise RuntimeError(f"chromium exited {run.returncode} without a screenshot: {run.stderr[-2000:]}")
    said = [m.group(1) for m in map(CONSOLE.search, run.stderr.splitlines()) if m]
    return [line for line in said if FAILED.search(line)]
