"""The gallery: every lecture entity built, cross-checked against OCCT and exported.

Each module in this package (one per area: synthetic, analytic_surfaces, swept, beyond, …) lists its
entries with :func:`entry`; :func:`entries` collects them all in module order.  An entry
is a small function that builds the object, so nothing is built at import time.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Entry:
    """One gallery row: ``name`` (file stem), the lecture entity, the surfmod call and
    the OCCT construct it maps onto, and ``build()`` returning a surfmod surface (or a
    build123d shape for solids)."""

    name: str
    entity: str
    call: str
    build: Callable[[], object]


_REGISTRY: dict[str, list[Entry]] = {}


def entry(name: str, entity: str, call: str):
    """Decorator registering ``build`` as a gallery entry of the calling module."""

    def register(build):
        _REGISTRY.setdefault(build.__module__, []).append(Entry(name, entity, call, build))
        return build

    return register


def entries() -> list[Entry]:
    """All entries of all gallery modules, sorted by module name then definition order."""
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if not info.name.startswith("_") and info.name != "runner":
            importlib.import_module(f"{__name__}.{info.name}")
    return [e for module in sorted(_REGISTRY) for e in _REGISTRY[module]]
