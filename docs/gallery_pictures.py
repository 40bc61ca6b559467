"""Make the pictures of the gallery page from ``surfmod gallery``'s own output.

    python docs/gallery_pictures.py            # runs `surfmod gallery` into a temporary folder
    python docs/gallery_pictures.py OUTDIR     # uses the PNGs an earlier `surfmod gallery OUTDIR` wrote

Each entity's PNG is copied into ``docs/gallery/`` scaled down to WIDTH pixels with a
palette, so the committed pictures stay small; the page itself (``gallery.md``) lists whatever pictures
are there, with each entry's lecture entity and call.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

HERE = Path(__file__).resolve().parent
TARGET = HERE / "gallery"
WIDTH = 320


def copy_pictures(outdir: Path, target: Path = TARGET, width: int = WIDTH) -> list[Path]:
    pictures = sorted(outdir.glob("*.png"))
    if not pictures:
        raise SystemExit(f"outdir: no PNG in {outdir}; run `surfmod gallery {outdir}` first")
    target.mkdir(exist_ok=True)
    written = []
    for png in pictures:
        with Image.open(png) as im:
            im = im.convert("RGB")
            height = round(im.height * width / im.width)
            # a 128-colour palette keeps the shading and makes each file a few kB
            small = im.resize((width, height), Image.Resampling.LANCZOS).quantize(colors=128)
            path = target / png.name
            small.save(path, optimize=True)
            written.append(path)
    return written


def main(argv: list[str]) -> int:
    if argv:
        written = copy_pictures(Path(argv[0]))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            subprocess.run(["surfmod", "gallery", tmp, "--no-progress"], check=True)
            written = copy_pictures(Path(tmp))
    print(f"{len(written)} pictures in {TARGET}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
