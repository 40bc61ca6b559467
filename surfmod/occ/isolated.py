"""What the STEP reader process runs (:func:`surfmod.inputs.read_step_file` starts it and
talks to it): OCCT's reader, the shape's numbers checked, the shape handed back as BinTools
bytes.

OCCT's STEP reader dereferences whatever the file says: a deleted line, a flipped byte or
a NaN coordinate can make it crash with SIGSEGV or loop forever, and neither can be caught
inside the process.  So these two functions run in a child; this module imports OCCT
inside them, so that the parent can name them (and start the child) before it loads OCCT
itself: the two imports overlap.
"""

from __future__ import annotations

import os


def load_occt() -> int:
    """The reader child's warm-up: OCCT's STEP reader imported before the first file."""
    from . import step  # noqa: F401

    return os.getpid()


def read_and_check(path: str, max_coordinate: float) -> tuple[bytes, list]:
    """Read ``path`` with OCCT, check its coordinates, return the shape as BinTools bytes
    and what the model says of its solids' orientation: those inside out in the file,
    read outward (:func:`~surfmod.occ.step.outward_solids`), and those whose faces
    disagree (:func:`~surfmod.occ.solids.faces_at_odds`)."""
    from .properties import check_coordinates
    from .solids import faces_at_odds
    from .step import brep_bytes, read_step

    turned: list = []  # the solids inside out in the file, turned outward
    shape = read_step(path, turned)
    at_odds = faces_at_odds(shape)  # solids whose faces disagree: said, left to mesh and mass
    check_coordinates(shape, path, max_coordinate)
    return brep_bytes(shape), (turned, at_odds)
