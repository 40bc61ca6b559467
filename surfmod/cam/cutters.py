"""End mills as objects: one class per cutter (:class:`Ball`, :class:`Flat`, :class:`Bull`),
holding its shape and what follows from it.

A cutter's drop (:mod:`~surfmod.cam.drop_cutter`) and push (:mod:`~surfmod.cam.fiber_contact`)
are compiled and hold no Python object: its ``code`` chooses them there, in one place each.
:func:`cutter` is the one place a kind's name is looked up.  See :doc:`/design` (section "Cutters").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import checks
from ..errors import SurfmodError


@dataclass(frozen=True)
class Cutter:
    """A cutting end of ``radius`` whose edge is rounded with ``corner`` (see the module)."""

    radius: float
    corner: float
    kind: ClassVar[str] = ""  # its name in Tool, tool tables and ``kind:R[:r]`` texts
    code: ClassVar[int] = -1  # the compiled drop and push choose its routines by it
    numbers: ClassVar[int] = 1  # how many numbers its ``kind:R[:r]`` text holds
    plunges: ClassVar[bool] = False  # cuts at its centre: may plunge (else enters by a helix)

    @property
    def core(self) -> float:
        return self.radius - self.corner  # the flat bottom's radius

    def profile(self, d):
        """Height of the cutting end above the tip at distance ``d`` from the axis (inf beyond
        the radius)."""
        d = np.asarray(d, dtype=float)
        c, t = self.corner, np.maximum(d - self.core, 0.0)
        out = np.where(d <= self.radius * (1 + 1e-15), c - np.sqrt(np.maximum(c * c - t * t, 0.0)), np.inf)
        return float(out) if out.ndim == 0 else out

    def stepover_for_scallop(self, scallop: float) -> float:
        """Stepover leaving cusps of height ``scallop`` on flat ground: ``2 sqrt(2 c h − h²)``
        for the corner of radius ``c``, plus the flat core's width ``2 (R − c)``."""
        h = checks.positive(scallop, "scallop")
        if h >= self.radius:
            raise SurfmodError(f"scallop: must be smaller than the tool radius {self.radius:g}, got {h:g}")
        return float(2.0 * self.core + self.cusp_spacing(h))

    def cusp_spacing(self, h: float) -> float:
        """Distance between passes of the corner's circle leaving cusps ``h``."""
        c, h = self.corner, min(h, self.corner)
        return 2.0 * math.sqrt(max(2.0 * c * h - h * h, 0.0))

    def scallop_for_stepover(self, stepover: float) -> float:
        """Cusp height on flat ground for a given stepover (0 where the core spans it)."""
        c, half = self.corner, stepover / 2.0 - self.core
        if half <= 0:
            return 0.0
        return float(c - np.sqrt(max(c * c - half * half, 0.0)))

    def wall_cusp(self, spacing: float, slope: float) -> float:
        """Cusp height, normal to a plane wall of ``slope`` degrees, between two positions
        of the tool (axis up) touching it ``spacing`` apart along it: waterline contours on
        a wall.  The tool's section through its axis is the half-strip of the core
        (``|r| ≤ R − c``, ``z ≥ c``: flat bottom, flanks going up) grown by the corner's
        disc; in the wall's frame (``t`` along it, ``d`` off it) its near side is the least
        of the discs round the strip's two corners and the strip's two edges moved ``c``
        towards the wall, each where it holds; the cusp stands where the near sides of the
        two positions cross (found by halving: the near side is convex).  A ball's is the
        circle's cusp below the equator and 0 on a vertical wall, where the flank sweeps
        everything between the contours.

        >>> round(Bull(3.0, 1.0).wall_cusp(2.5, 70.0), 4), Bull(3.0, 1.0).wall_cusp(2.5, 90.0)
        (0.5254, 0.0)
        """
        c, core = self.corner, self.core
        beta = math.radians(90.0 - min(max(float(slope), 0.0), 90.0))  # the wall's normal below horizontal
        sb, cb = math.sin(beta), math.cos(beta)

        def near(t):
            """The tool's distance from the wall at ``t`` along it from the contact (inf off it)."""
            best = math.inf
            for t0, d0 in ((0.0, 0.0), (-2.0 * core * sb, 2.0 * core * cb)):  # the strip's corners
                if abs(t - t0) <= c:
                    best = min(best, d0 + c - math.sqrt(c * c - (t - t0) ** 2))
            if cb > 0.0 and t >= c * sb:  # the flank, going up
                best = min(best, c * (1.0 - cb) + (t - c * sb) * sb / cb)
            if sb > 0.0 and -c * cb - 2.0 * core * sb <= t <= -c * cb:  # the flat bottom, going down
                best = min(best, c * (1.0 - sb) + (-t - c * cb) * cb / sb)
            return best

        lo, hi = 0.0, float(spacing)  # the lower position's near side rises from 0, the upper's falls to 0
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if near(mid) < near(mid - spacing) else (lo, mid)
        return float(min(near(lo), near(lo - spacing)))

    def grown(self, g: float) -> Cutter:
        """The cutter grown by ``g`` in every direction (tip ``g`` lower), keeping this one ``g`` off."""
        return Bull(self.radius + g, self.corner + g)

    def roughing_offset(self, allowance: float) -> Cutter:
        """A cutter whose drop height, plus ``allowance``, keeps this one at least that far
        from the part: the flat end ``R + A`` holds :meth:`grown`, drops ten times faster,
        and stays up to ``A (sin θ + cos θ - 1)`` further away on a slope θ (≤ 0.41 A)."""
        return Flat(self.radius + allowance)

    def pass_gap(self, circle: float, slope: float) -> float:
        """Raster passes' distance across a ``slope`` (degrees) for cusps ``circle`` apart on it."""
        return circle * math.cos(math.radians(slope))

    # its texts: in a tool's name (job summaries, program comments), a tool path's summary
    # line, and a tool path's G-code header comment
    @property
    def name(self) -> str:
        return f"{self.kind} end mill"

    @property
    def summary(self) -> str:
        return f"{self.kind} end mill r={self.radius:g}"

    @property
    def comment(self) -> str:
        return f"{self.kind} end mill radius {self.radius:g} mm"


@dataclass(frozen=True)
class Ball(Cutter):
    """A ball end: a sphere of radius ``R`` centred ``R`` above the tip."""

    corner: float = 0.0  # 0 or the radius: it is the radius
    kind: ClassVar[str] = "ball"
    code: ClassVar[int] = 0
    plunges: ClassVar[bool] = True

    def __post_init__(self):
        if self.corner not in (0.0, self.radius):
            raise SurfmodError(f"corner_radius: a ball end mill has none, got {self.corner:g}")
        object.__setattr__(self, "corner", self.radius)

    def grown(self, g: float) -> Cutter:
        return Ball(self.radius + g)

    def roughing_offset(self, allowance: float) -> Cutter:
        return Ball(self.radius + allowance)  # exact, and as fast as the flat end


@dataclass(frozen=True)
class Flat(Cutter):
    """A flat end: a disc at the tip."""

    corner: float = 0.0
    kind: ClassVar[str] = "flat"
    code: ClassVar[int] = 1

    def __post_init__(self):
        if self.corner != 0.0:
            raise SurfmodError(f"corner_radius: a flat end mill has none, got {self.corner:g}")

    def stepover_for_scallop(self, scallop: float) -> float:
        checks.positive(scallop, "scallop")
        raise SurfmodError("scallop: a flat end mill leaves no scallop on flat ground; give stepover instead")


@dataclass(frozen=True)
class Bull(Cutter):
    """A bull nose: a flat core of radius ``R - c`` rounded by a torus of corner radius ``c``."""

    kind: ClassVar[str] = "bull"
    code: ClassVar[int] = 2
    numbers: ClassVar[int] = 2

    def __post_init__(self):
        if not 0.0 < self.corner < self.radius:
            raise SurfmodError(f"corner_radius: a bull nose needs 0 < corner radius < radius {self.radius:g}, "
                               f"got {self.corner:g}")

    def pass_gap(self, circle: float, slope: float) -> float:
        # the flat core counts only on level ground
        return 2.0 * self.core + circle if slope < 1.0 else super().pass_gap(circle, slope)

    @property
    def name(self) -> str:
        return f"bull nose (corner r={self.corner:g})"

    @property
    def summary(self) -> str:
        return f"{super().summary} corner r={self.corner:g}"


#: the cutters by kind
CUTTERS = {c.kind: c for c in (Flat, Ball, Bull)}


def cutter(kind, radius, corner: float = 0.0) -> Cutter:
    """The cutter of ``kind`` (``"flat"``, ``"ball"`` or ``"bull"``), ``radius`` > 0 and,
    for a bull nose, ``corner`` radius.

    >>> cutter("bull", 3.0, 0.5).core, cutter("ball", 2).corner
    (2.5, 2.0)
    """
    shape = CUTTERS.get(kind) if isinstance(kind, str) else None
    if shape is None:
        raise SurfmodError(f"tool: kind must be 'flat', 'ball' or 'bull', got {kind!r}")
    return shape(checks.positive(radius, "tool radius"), float(corner))
