"""Exceptions raised by surfmod.

Every problem with user input is a :class:`SurfmodError` (a ``ValueError``) whose
message names the offending argument.  Failures inside OpenCASCADE are re-raised as
:class:`KernelError` (a subclass, so ``except SurfmodError`` catches both) carrying the
operation that failed, never as a raw ``Standard_Failure``.
"""

from __future__ import annotations


class SurfmodError(ValueError):
    """Bad input to a surfmod call; the message names the argument.

    >>> import surfmod as sm
    >>> try:
    ...     sm.plane((0, 0, 0), (1, 0, 0), (2, 0, 0))
    ... except sm.SurfmodError as exc:
    ...     print("p2" in str(exc))
    True
    """


class KernelError(SurfmodError):
    """OpenCASCADE refused or failed an operation; the message says which one.

    Like :class:`SurfmodError` it is a ``ValueError``, so one ``except`` catches both:

    >>> import surfmod as sm
    >>> issubclass(sm.KernelError, sm.SurfmodError) and issubclass(sm.KernelError, ValueError)
    True
    """


class DamagedFileError(KernelError):
    """A file exists but OCCT could not give a usable shape from it: it is truncated or
    corrupt, its coordinates are NaN or huge, or the reader crashed or ran past its time
    limit (it reads in a child process, so none of this takes the caller down).  The
    message names the file.  The command line exits with status 1 on it.

    >>> import surfmod as sm
    >>> issubclass(sm.DamagedFileError, sm.KernelError)
    True
    """


class MissingExtraError(SurfmodError, ImportError):
    """A call needs an optional package that is not installed; the message names the
    package and the extra that brings it (``pip install "surfmod[fem]"``).  It is both a
    :class:`SurfmodError` (the command line prints its one line and exits 1) and an
    ``ImportError``.

    >>> import surfmod as sm
    >>> issubclass(sm.MissingExtraError, sm.SurfmodError) and issubclass(sm.MissingExtraError, ImportError)
    True
    """


class RoundTripWarning(UserWarning):
    """A file was written, but reading it back gives a shape that differs from the one
    given (a solid lost or turned, faces lost, a volume or centroid moved); the message
    names what changed and by how much.  ``strict=True`` raises :class:`SurfmodError`
    instead and writes nothing.

    >>> import surfmod as sm
    >>> issubclass(sm.RoundTripWarning, UserWarning)
    True
    """


class InsideOutWarning(UserWarning):
    """A solid encloses a negative volume (its faces point into its material): the
    message names the solid and the volume.  Readers and meshing turn such a solid
    outward by the sign of its enclosed volume (never face by face) and say so with this
    warning; the command line prints it as one line.

    >>> import surfmod as sm
    >>> issubclass(sm.InsideOutWarning, UserWarning)
    True
    """
