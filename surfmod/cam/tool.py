"""End mills (flat, ball, bull nose) and the tool table of a job.

A tool is its cutting end (profile ``f(d)``: the height of the end above the tip at
distance ``d`` from the axis) with flutes ``flute_length`` long, above them a shank that
does not cut and the holder it sits in (:attr:`Tool.body`: what must clear the part and the
stock, :mod:`surfmod.cam.holder`).  The table (number, speeds and feeds, flutes, shank and
holder of each tool) comes from a TOML or JSON file or from defaults.
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import checks
from ..errors import SurfmodError
from .cutters import CUTTERS, cutter

#: Default spindle speed (rpm) and feeds (mm/min): a 6 mm carbide end mill in aluminium,
#: scaled by the diameter (surface speed and chip load held); the plunge/ramp feed a third.
DEFAULT_SURFACE_SPEED = 200.0  # m/min
DEFAULT_CHIP_LOAD = 0.04  # mm per tooth, two flutes
MAX_SPINDLE = 24000.0
#: Default shank and holder, in tool radii: the shank sticks out this far above the flutes,
#: the holder is a cylinder this wide (of the wider of the end and the shank) and this long.
DEFAULT_SHANK_LENGTH = 2.0
DEFAULT_HOLDER_RADIUS = 2.5
DEFAULT_HOLDER_LENGTH = 8.0
#: Slices of a cone holder widening upwards: each is held as a cylinder of its top radius
#: standing at its bottom (the cone inside it, at most ``(top - bottom radius) / CONE_SLICES``
#: wider than the cone).
CONE_SLICES = 8
SHAPE = frozenset({"corner", "core", "profile", "stepover_for_scallop", "scallop_for_stepover"})  # its cutter's


@dataclass(frozen=True)
class Tool:
    """An end mill: ``kind`` ``"flat"``, ``"ball"`` or ``"bull"``, ``radius`` > 0, and for a
    bull nose its ``corner_radius`` (``0 < corner_radius < radius``: a flat core of radius
    ``radius - corner_radius`` rounded by a torus).  ``flute_length`` (default three
    diameters) is its cutting length (how deep it goes is its shank's and holder's to
    say); ``number`` (the T word), ``spindle`` (rpm), ``feed`` and ``plunge_feed``
    (mm/min) default from the diameter.  Its shape is
    ``cutter``, a :class:`~surfmod.cam.cutters.Cutter`, which also answers for the tool
    ``corner`` (the corner radius: the radius for a ball, 0 for a flat end), ``core`` (the
    flat bottom's radius), ``profile(d)``, ``stepover_for_scallop(h)`` and
    ``scallop_for_stepover(s)``.

    Above the flutes the tool does not cut: a shank of ``shank_radius`` (default the
    radius) sticks out ``shank_length`` (default two radii) into a holder of
    ``holder_radius`` (default 2.5 times the wider of the radius and the shank's) and
    ``holder_length`` (default eight radii); a ``holder_top_radius`` other than the holder
    radius makes the holder a cone (the collet nut's taper).  The spindle above the holder
    is not modelled.  :attr:`body` is that stack as discs.

    >>> import surfmod as sm
    >>> t = sm.Tool("ball", 3.0)
    >>> round(t.stepover_for_scallop(0.01), 6)
    0.48949
    >>> b = sm.Tool("bull", 4.0, 1.0)
    >>> round(b.stepover_for_scallop(0.01), 6), b.profile(2.0), b.profile(4.0)
    (6.282135, 0.0, 1.0)
    """

    kind: str
    radius: float
    corner_radius: float = 0.0
    flute_length: float | None = None
    number: int | None = None
    spindle: float | None = None
    feed: float | None = None
    plunge_feed: float | None = None
    shank_radius: float | None = None
    shank_length: float | None = None
    holder_radius: float | None = None
    holder_length: float | None = None
    holder_top_radius: float | None = None

    def __post_init__(self):
        object.__setattr__(self, "cutter", cutter(self.kind, self.radius, self.corner_radius))
        object.__setattr__(self, "radius", self.cutter.radius)
        object.__setattr__(self, "corner_radius", float(self.corner_radius))
        flute = 6.0 * self.radius if self.flute_length is None else checks.positive(self.flute_length, "flute_length")
        object.__setattr__(self, "flute_length", flute)
        if self.number is not None:
            object.__setattr__(self, "number", checks.count(self.number, "number", 1, 99999))
        for name in ("spindle", "feed", "plunge_feed"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, checks.positive(getattr(self, name), name))
        r = self.radius
        shank = r if self.shank_radius is None else checks.positive(self.shank_radius, "shank_radius")
        stick = DEFAULT_SHANK_LENGTH * r if self.shank_length is None else checks.real(self.shank_length,
                                                                                       "shank_length")
        if stick < 0:
            raise SurfmodError(f"shank_length: must be >= 0, got {self.shank_length!r}")
        holder = (DEFAULT_HOLDER_RADIUS * max(r, shank) if self.holder_radius is None
                  else checks.positive(self.holder_radius, "holder_radius"))
        if holder < shank:
            raise SurfmodError(f"holder_radius: {holder:g} is narrower than the shank radius {shank:g}")
        length = (DEFAULT_HOLDER_LENGTH * r if self.holder_length is None
                  else checks.positive(self.holder_length, "holder_length"))
        top = holder if self.holder_top_radius is None else checks.positive(self.holder_top_radius,
                                                                            "holder_top_radius")
        for name, value in (("shank_radius", shank), ("shank_length", stick), ("holder_radius", holder),
                            ("holder_length", length), ("holder_top_radius", top)):
            object.__setattr__(self, name, float(value))

    @property
    def body(self) -> np.ndarray:
        """The parts above the flutes that must not touch anything, as discs ``(K, 3)``:
        radius, the height of its bottom above the tip and its length, lowest first: the shank (even
        one no wider than the end meets the stock above the flutes in front of it), then
        the holder; a cone holder widening upwards is held by :data:`CONE_SLICES` cylinders
        each as wide as its slice's top.

        >>> Tool("flat", 2.0, shank_radius=3.0, shank_length=5.0, flute_length=10.0).body.tolist()
        [[3.0, 10.0, 5.0], [7.5, 15.0, 16.0]]
        """
        bottom = self.flute_length + self.shank_length
        discs = [(self.shank_radius, self.flute_length, self.shank_length)]
        rb, rt, length = self.holder_radius, self.holder_top_radius, self.holder_length
        if rt > rb:
            discs += [(rb + (rt - rb) * (k + 1) / CONE_SLICES, bottom + length * k / CONE_SLICES, length / CONE_SLICES)
                      for k in range(CONE_SLICES)]
        else:
            discs.append((rb, bottom, length))
        return np.array(discs, float)

    @property
    def diameter(self) -> float:
        return 2.0 * self.radius

    def __getattr__(self, name):
        if name in SHAPE:
            return getattr(self.cutter, name)
        raise AttributeError(f"'Tool' object has no attribute {name!r}")

    def with_defaults(self, number: int) -> "Tool":
        """This tool with ``number`` (unless it has one) and speeds and feeds filled in."""
        rpm = self.spindle or min(DEFAULT_SURFACE_SPEED * 1000.0 / (np.pi * self.diameter), MAX_SPINDLE)
        feed = self.feed or 2 * DEFAULT_CHIP_LOAD * rpm * min(1.0, self.diameter / 6.0)
        return replace(self, number=self.number or number, spindle=float(round(rpm)),
                       feed=float(round(feed)), plunge_feed=self.plunge_feed or float(round(feed / 3)))

    def __str__(self) -> str:
        return f"T{self.number or '?'} {self.cutter.name} r={self.radius:g}"


def parse_tool(text: str, name: str = "tool") -> Tool:
    """``"flat:R"``, ``"ball:R"`` or ``"bull:R:r"`` (radius, corner radius in mm) as a Tool.

    >>> t = parse_tool("bull:3:0.5")
    >>> t.kind, t.radius, t.corner_radius, t.flute_length, t.holder_radius
    ('bull', 3.0, 0.5, 18.0, 7.5)
    """
    parts = str(text).split(":")
    try:
        numbers = [float(p) for p in parts[1:]]
    except ValueError:
        raise SurfmodError(f"{name}: expected flat:R, ball:R or bull:R:r, got {text!r}") from None
    shape = CUTTERS.get(parts[0])
    if shape is None or len(numbers) != shape.numbers:
        raise SurfmodError(f"{name}: expected flat:R, ball:R or bull:R:r, got {text!r}")
    if not numbers[0] > 0:
        raise SurfmodError(f"radius: {name} radius must be > 0, got {numbers[0]:g}")
    return Tool(parts[0], *numbers)


def read_table(path, name: str, what: str) -> tuple[Path, object]:
    """The file ``path`` and what it holds, read as TOML (suffix ``.toml``) or else JSON: the
    tool table's and the machine table's reader; a missing or unreadable file is refused
    naming the argument ``name``."""
    p = Path(path)
    if not p.is_file():
        raise SurfmodError(f"{name}: no such file {str(path)!r}")
    try:
        return p, tomllib.loads(p.read_text()) if p.suffix.lower() == ".toml" else json.loads(p.read_text())
    except (tomllib.TOMLDecodeError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SurfmodError(f"{name}: {p.name} is not a {what}: {exc}") from None


def load_tool_table(path) -> dict[int, Tool]:
    """Tools by number from a TOML (``[[tool]]`` tables) or JSON (``{"tool": [...]}``) file;
    each entry has ``number``, ``kind``, ``radius`` and optionally ``corner_radius``,
    ``flute_length``, ``shank_radius``, ``shank_length``, ``holder_radius``,
    ``holder_length``, ``holder_top_radius``, ``spindle``, ``feed``, ``plunge_feed``.

    >>> import tempfile, os
    >>> p = os.path.join(tempfile.mkdtemp(), "tools.toml")
    >>> _ = open(p, "w").write('[[tool]]\\nnumber = 3\\nkind = "ball"\\nradius = 2\\nspindle = 18000\\n')
    >>> load_tool_table(p)[3].spindle
    18000.0
    """
    p, data = read_table(path, "tools", "tool table")
    entries = data.get("tool") if isinstance(data, dict) else None
    if not isinstance(entries, list):
        raise SurfmodError(f"tools: {p.name} has no list of [[tool]] entries")
    known = {"number", "kind", "radius", "corner_radius", "flute_length", "shank_radius", "shank_length",
             "holder_radius", "holder_length", "holder_top_radius", "spindle", "feed", "plunge_feed"}
    table = {}
    for k, entry in enumerate(entries):
        if not isinstance(entry, dict) or "number" not in entry or not set(entry) <= known:
            raise SurfmodError(f"tools: entry {k + 1} of {p.name} needs number, kind, radius and only {sorted(known)}")
        try:
            tool = Tool(**entry)
        except TypeError as exc:
            raise SurfmodError(f"tools: entry {k + 1} of {p.name}: {exc}") from None
        if tool.number in table:
            raise SurfmodError(f"tools: tool number {tool.number} appears twice in {p.name}")
        table[tool.number] = tool
    return table
