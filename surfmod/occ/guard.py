"""Turn OCCT exceptions (``Standard_Failure``) into :class:`~surfmod.errors.KernelError` with context."""

from __future__ import annotations

import contextlib

from ..errors import KernelError, SurfmodError


@contextlib.contextmanager
def kernel(what: str):
    """Run OCCT calls; any kernel failure becomes ``KernelError("<what>: ...")``.

    ``SurfmodError`` raised inside passes through unchanged.
    """
    try:
        yield
    except SurfmodError:
        raise
    except Exception as exc:  # OCP raises Standard_Failure subclasses and RuntimeError
        detail = str(exc) or type(exc).__name__
        raise KernelError(f"{what}: OCCT failed ({type(exc).__name__}: {detail})") from exc


def check_done(builder, what: str):
    """Raise ``KernelError`` when an OCCT ``BRepBuilderAPI``-style builder did not finish."""
    if not builder.IsDone():
        raise KernelError(f"{what}: OCCT builder reported failure")
    return builder
