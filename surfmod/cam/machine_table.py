"""The machine a job runs on (:class:`Machine`: axis limits, rapid rate, corner blending, tool
change time), read from a TOML or JSON table beside the tool table; what it leaves out keeps
the default.  See :doc:`/guide/cam` (section "Cycle time").

>>> import tempfile, os
>>> p = os.path.join(tempfile.mkdtemp(), "mill.toml")
>>> _ = open(p, "w").write('[machine]\\nmax_acceleration = [800, 800, 400]\\nblend_tolerance = 0.005\\n')
>>> m = load_machine_table(p)
>>> m.max_acceleration, m.max_velocity, m.blend_tolerance
((800.0, 800.0, 400.0), (5000.0, 5000.0, 3000.0), 0.005)
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .. import checks
from ..errors import SurfmodError
from .tool import read_table


def _axes(value, name: str) -> tuple:
    """Three per-axis limits (X, Y, Z), each > 0; one number stands for all three."""
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) != 3:
            raise SurfmodError(f"{name}: expected one number or three (X, Y, Z), got {len(value)}")
        return tuple(checks.positive(v, f"{name}[{k}]") for k, v in enumerate(value))
    x = checks.positive(value, name)
    return (x, x, x)


@dataclass(frozen=True)
class Machine:
    """A milling machine's limits, by default a small hobby/prosumer mill (stepper-driven
    ball screws, a desktop mill or a well-tuned router):

    - ``max_velocity`` (mm/min, per axis X, Y, Z; one number for all): 5000, 5000, 3000;
    - ``max_acceleration`` (mm/s², per axis): 500, 500, 250;
    - ``rapid`` (mm/min): the ``G0`` rate, 5000, further limited by the axes;
    - ``blend_tolerance`` (mm): how far the controller may leave a corner to keep speed,
      LinuxCNC's ``G64 P`` (naive-cam tolerance), grbl's junction deviation: 0.01; 0 stops
      at every corner (``G61``, exact path);
    - ``tool_change`` (s): 8.

    Each field is checked on its own and a bad one refused naming it.

    >>> Machine(max_velocity=6000).max_velocity
    (6000.0, 6000.0, 6000.0)
    >>> Machine(blend_tolerance=-1)
    Traceback (most recent call last):
    ...
    surfmod.errors.SurfmodError: blend_tolerance: must be >= 0, got -1
    """

    max_velocity: tuple = (5000.0, 5000.0, 3000.0)
    max_acceleration: tuple = (500.0, 500.0, 250.0)
    rapid: float = 5000.0
    blend_tolerance: float = 0.01
    tool_change: float = 8.0

    def __post_init__(self):
        object.__setattr__(self, "max_velocity", _axes(self.max_velocity, "max_velocity"))
        object.__setattr__(self, "max_acceleration", _axes(self.max_acceleration, "max_acceleration"))
        object.__setattr__(self, "rapid", checks.positive(self.rapid, "rapid"))
        object.__setattr__(self, "blend_tolerance", checks.real(self.blend_tolerance, "blend_tolerance", low=0.0))
        object.__setattr__(self, "tool_change", checks.real(self.tool_change, "tool_change", low=0.0))

    def __str__(self) -> str:
        v, a = self.max_velocity, self.max_acceleration
        return (f"machine: axes {v[0]:g}/{v[1]:g}/{v[2]:g} mm/min, {a[0]:g}/{a[1]:g}/{a[2]:g} mm/s², "
                f"rapid {self.rapid:g} mm/min, blending {self.blend_tolerance:g} mm, tool change {self.tool_change:g} s")


#: The default machine of every job.
MACHINE = Machine()


def load_machine_table(path) -> Machine:
    """A :class:`Machine` from a TOML (``[machine]`` table) or JSON (``{"machine": {...}}``)
    file; the fields it does not give keep their defaults, a field it does not know is
    refused."""
    p, data = read_table(path, "machine", "machine table")
    entry = data.get("machine") if isinstance(data, dict) else None
    if not isinstance(entry, dict):
        raise SurfmodError(f"machine: {p.name} has no [machine] table")
    known = {f.name for f in fields(Machine)}
    unknown = sorted(set(entry) - known)
    if unknown:
        raise SurfmodError(f"machine: {p.name} gives {', '.join(unknown)}; known fields are {', '.join(sorted(known))}")
    return Machine(**entry)
