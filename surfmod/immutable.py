"""Immutable values: the one way surfmod surfaces and curves are built and cached.

A public attribute binds once, while the object is built: rebinding it would leave the
caches derived from it (homogeneous net, OCCT twin) stale, so it is refused.  The class's
``__init__`` validates user input; ``cls._construct_fast(**fields)`` binds data made inside
surfmod as given.  A twin cached with :meth:`_twin` is shared: copy it before modifying it
in place (``Segment``, ``Transform``).  See :doc:`/design` (section "Values, not objects
that change").
"""

from __future__ import annotations

from .errors import SurfmodError


class ImmutableError(SurfmodError, AttributeError):
    """An attempt to rebind or delete an attribute of a surfmod value.

    >>> import surfmod as sm
    >>> s = sm.sphere(1.0)
    >>> try:
    ...     s.radius = 2.0
    ... except AttributeError as exc:
    ...     print(type(exc).__name__)
    ImmutableError
    """


class Immutable:
    """Base of surfmod's value objects: public attributes bind once; private caches may fill in."""

    __slots__ = ()

    def __setattr__(self, name: str, value) -> None:
        if not name.startswith("_") and name in self.__dict__:
            raise ImmutableError(
                f"{name}: {type(self).__name__} is immutable; build a new one "
                "(e.g. with transformed(), segment() or the constructor)"
            )
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        raise ImmutableError(f"{name}: {type(self).__name__} is immutable; its attributes cannot be deleted")

    @classmethod
    def _construct_fast(cls, **fields):
        """An instance with ``fields`` bound as given: no validation (trusted data only)."""
        obj = object.__new__(cls)
        for name, value in fields.items():
            object.__setattr__(obj, name, value)
        return obj

    def _twin(self, build):
        """The cached OCCT counterpart, built by ``build()`` on the first call."""
        twin = self.__dict__.get("_occt_twin")
        if twin is None:
            twin = build()
            object.__setattr__(self, "_occt_twin", twin)
        return twin
