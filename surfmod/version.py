"""surfmod's version, as pip recorded it when the package was installed.

The one place the version is written is ``pyproject.toml``; a wheel, an sdist and an
editable install all carry it in their metadata, which is what ``sm.__version__`` and
``surfmod --version`` report.
"""

from __future__ import annotations

#: What a source tree put on ``sys.path`` without being installed reports.
NOT_INSTALLED = "0+unknown (not installed)"


def installed_version(distribution: str = "surfmod") -> str:
    """The installed distribution's version, or :data:`NOT_INSTALLED` when pip has no record
    of it (the version is never guessed from files beside the package).

    >>> import importlib.metadata
    >>> installed_version() == importlib.metadata.version("surfmod")
    True
    >>> installed_version("no-such-distribution")
    '0+unknown (not installed)'
    """
    import importlib.metadata  # 0.19 s: paid by sm.__version__ and --version alone

    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return NOT_INSTALLED
