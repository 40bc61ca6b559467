"""The material regions of a solid whose boundary touches itself.

Real parts carry solids whose shells meet along a curve without sharing an edge there:
pythonocc_11752.stp has an inner void shell (a blind bore) whose rim circle lies on the
outer shell, where a boss is attached by that same circle only.  The two shells hold two
distinct, coincident circle edges, which any triangulation discretizes independently, so
the triangles on either side cross each other.  ``BOPAlgo_MakerVolume`` (OCCT's general
fuse of faces into the volumes they bound) intersects the faces, merges coincident edges
and splits space into closed regions; the regions on the material side of the original
faces are the solid, each with a manifold boundary that shares its contact edges with its
neighbours.
"""

from __future__ import annotations

from ..errors import KernelError
from .guard import kernel
from .topo import explore, solids_of, wrapped
from OCP.BOPAlgo import BOPAlgo_MakerVolume
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
from .properties import gprops
from .bindings import TopTools_ListOfShape

#: The regions' BRepGProp volumes must add up to the solid's within this relative error
#: (both at eps 1e-9): anything else means a region was misclassified or lost.
VOLUME_AGREEMENT = 1e-7


def material_regions(solid) -> list:
    """The solid's material split into regions with manifold, non-crossing boundaries
    (``TopoDS_Solid`` list): the volumes ``BOPAlgo_MakerVolume`` builds from the solid's
    faces, kept where their faces keep the orientation the solid gives them (the
    material side); voids and outside pockets the faces enclose are dropped.  Raises
    ``KernelError`` when OCCT fails or the kept volumes do not add up to the solid's.

    >>> import build123d as bd
    >>> from surfmod.occ.properties import gprops
    >>> hollow = bd.Box(4, 4, 4) - bd.Box(2, 2, 2)  # a solid with an inner void shell
    >>> [round(gprops(r)["volume"], 9) for r in material_regions(hollow.wrapped)]
    [56.0]
    """
    solid = wrapped(solid)
    with kernel("BOPAlgo_MakerVolume (material regions)"):
        maker = BOPAlgo_MakerVolume()
        maker.SetRunParallel(False)  # the machine's cores belong to the caller
        maker.SetIntersect(True)
        faces = list(explore(solid, TopAbs_FACE))
        arguments = TopTools_ListOfShape()
        for face in faces:
            arguments.Append(face)
        maker.SetArguments(arguments)
        maker.Perform()
        if maker.HasErrors():
            raise KernelError("BOPAlgo_MakerVolume (material regions): OCCT reported errors")
        # each image face, as oriented in the solid's own faces: material lies behind it
        side: dict = {}  # shape hash (orientation-blind) -> the images with that hash
        for face in faces:
            for image in list(maker.Modified(face)) or [face]:
                side.setdefault(image.__hash__(), []).append(image)

        def same_side(face):
            for image in side.get(face.__hash__(), ()):
                if image.IsSame(face):
                    return face.Orientation() == image.Orientation()
            return None

        kept = []
        for region in explore(maker.Shape(), TopAbs_SOLID):
            votes = [v for v in map(same_side, explore(region, TopAbs_FACE)) if v is not None]
            if votes and all(votes):
                kept.append(region)
            elif any(votes):
                raise KernelError("BOPAlgo_MakerVolume (material regions): a region lies on both sides of the solid's faces")
    kept = [s for r in kept for s in solids_of(r)]
    total = sum(abs(gprops(r)["volume"]) for r in kept)
    expected = abs(gprops(solid)["volume"])
    if not kept or abs(total - expected) > VOLUME_AGREEMENT * expected:
        raise KernelError(f"BOPAlgo_MakerVolume (material regions): the regions hold {total:.10g}, "
                          f"the solid {expected:.10g}")
    return kept
