"""Reading OCCT / build123d faces back into surfmod: the one read-back path.

``from_face`` (in :mod:`.trimmed`) gives a :class:`TrimmedFace`: the untrimmed surface
read by :mod:`.readers` in OCCT's parametrization, evaluated wherever the face lives, with
the face's boundary kept.  Mass properties, sections, ``check``, tessellation and tool
paths read faces only through here.
"""

from .readers import read_curve, read_surface
from .trimmed import TrimmedFace, from_face, from_faces, surface_of

__all__ = ["TrimmedFace", "from_face", "from_faces", "read_curve", "read_surface", "surface_of"]
