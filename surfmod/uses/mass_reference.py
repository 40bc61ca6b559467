"""The independent reference for mass properties, and the verdict of ``surfmod mass``.

When the :mod:`surfmod.mass` pipeline and plain ``BRepGProp`` differ, :func:`refined_props`
(BRepGProp on faces split ``k × k``, ``k`` in :data:`SPLITS`) and then :func:`kronrod_props`
(its Gauss–Kronrod rule with the moments converged, in a child process:
:func:`kronrod_props_within`) decide which is right, both about the solid's vertex mean, the
point and fields surfmod uses.  :func:`judge` is the command's verdict on one solid.
See :doc:`/guide/uses` (section "Checked against BRepGProp and the references").
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from .. import child, tolerances
from ..errors import SurfmodError

#: the pieces per face direction, coarsest first
SPLITS = (1, 2, 4, 8)
#: the change of one refinement below which the refined reference is taken as settled
CONVERGED = 1e-11
#: seconds the references may take to settle a disagreement (each refinement's cost is
#: estimated from the one before it, before it starts)
REFERENCE_BUDGET = 60.0
#: exit code when surfmod and BRepGProp differ by less than the model's own ambiguity
EXIT_AMBIGUOUS = 3
#: exit code when they differ by more (a real disagreement)
EXIT_DISAGREE = 4


@dataclass(frozen=True)
class RefinedProps:
    """Volume, area, centroid and inertia about the centroid (OCCT's convention, ``Ixy =
    -∫xy``) at the finest refinement ``splits`` run, integrated about ``location``;
    ``changes`` the last refinement's change of the volume and area (relative), the
    centroid (relative to the volume's cube root) and the inertia (relative to its largest
    entry): the error estimate."""

    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray
    location: np.ndarray
    splits: int
    faces: int
    changes: dict
    seconds: float

    @property
    def converged(self) -> bool:
        return max(self.changes.values()) <= CONVERGED


@dataclass(frozen=True)
class KronrodProps:
    """Volume, area, centroid and inertia about the centroid by the Gauss–Kronrod rule at
    ``eps``; ``error`` its own estimate of the relative error of the whole solid's
    properties (each quantity relative to its own size, so conservative: a torus centred at
    the origin reports 8e-9 with its volume and inertia exact to 3e-15)."""

    volume: float
    area: float
    centroid: np.ndarray
    inertia: np.ndarray
    eps: float
    error: float
    seconds: float


def relative_differences(r, o) -> dict:
    """Mass properties ``r`` against ``o`` (anything with ``volume``, ``area``, ``centroid``
    and ``inertia``: surfmod's, BRepGProp's, a reference's): volume and area relative, the
    centroid relative to the volume's cube root, the inertia to its largest entry, all of
    ``o``.

    >>> from types import SimpleNamespace as P
    >>> a = P(volume=8.0, area=24.0, centroid=(0, 0, 0), inertia=[[1.0, 0], [0, 2.0]])
    >>> b = P(volume=8.0, area=24.0, centroid=(0, 0, 2e-6), inertia=[[1.0, 0], [0, 2.0]])
    >>> {k: float(v) for k, v in relative_differences(b, a).items()}
    {'volume': 0.0, 'area': 0.0, 'centroid': 1e-06, 'inertia': 0.0}
    """
    length = max(abs(o.volume), 1e-300) ** (1 / 3)
    big = max(float(np.abs(np.asarray(o.inertia)).max()), 1e-300)
    return {
        "volume": abs(r.volume - o.volume) / max(abs(o.volume), 1e-300),
        "area": abs(r.area - o.area) / max(abs(o.area), 1e-300),
        "centroid": float(np.abs(np.asarray(r.centroid) - np.asarray(o.centroid)).max()) / length,
        "inertia": float(np.abs(np.asarray(r.inertia) - np.asarray(o.inertia)).max()) / big,
    }


def refined_props(shape, *, location=None, eps: float = 1e-13, budget: float = 60.0) -> RefinedProps:
    """Volume, area, centroid and inertia of the solid ``shape`` by ``BRepGProp`` on its faces
    split ``k × k`` (``k`` in :data:`SPLITS`, until a refinement changes every quantity by
    less than :data:`CONVERGED`), all about ``location`` (default: the vertex mean of the
    shape, BRepGProp's and surfmod's reference point).  ``SurfmodError`` naming ``budget``
    when the next refinement would take longer than the seconds left (estimated as four
    times the last one, before it starts).

    >>> import build123d as bd
    >>> r = refined_props(bd.Torus(10, 2).wrapped)
    >>> round(r.volume, 9), bool(r.converged), r.splits
    (789.568352087, True, 2)
    """
    from ..occ.properties import gprops_about, split_faces, vertex_mean
    from ..occ.topo import faces_of, solids_of

    if not solids_of(shape):
        raise SurfmodError("shape: has no solid to weigh")
    location = vertex_mean(shape) if location is None else np.asarray(location, dtype=float)
    start = time.perf_counter()
    previous, changes, last = None, {}, 0.0
    for k in SPLITS:
        now = time.perf_counter()
        if previous is not None and now + 4 * last > start + budget:
            raise SurfmodError(f"budget: refining the faces {k} x {k} would take about {4 * last:.0f} s, more than the "
                               f"{start + budget - now:.0f} s left of {budget:g} s")
        split = split_faces(shape, k)
        current = SimpleNamespace(**gprops_about(split, location, eps))
        last = time.perf_counter() - now
        if previous is not None:
            changes = relative_differences(previous, current)
            if max(changes.values()) <= CONVERGED:
                break
        previous = current
    return RefinedProps(current.volume, current.area, current.centroid, current.inertia, location, k,
                       len(faces_of(split)), changes, time.perf_counter() - start)


def kronrod_props(shape, eps: float = 1e-10) -> KronrodProps:
    """Mass properties of the solid ``shape`` by ``BRepGProp.VolumePropertiesGK`` (centroid
    and inertia converged as well as the volume); the area by ``BRepGProp.SurfaceProperties``
    at the same ``eps``.

    >>> import build123d as bd, math
    >>> r = kronrod_props(bd.Cylinder(1, 2).wrapped)
    >>> abs(r.volume - 2 * math.pi) < 1e-13, round(float(r.inertia[2, 2] / math.pi), 12), r.error < 1e-12
    (True, 1.0, True)
    """
    from ..occ.properties import gauss_kronrod
    from ..occ.topo import solids_of

    if not solids_of(shape):
        raise SurfmodError("shape: has no solid to weigh")
    eps = float(eps)
    if not 1e-15 <= eps < 1:
        raise SurfmodError(f"eps: expected a relative tolerance in [1e-15, 1), got {eps!r}")
    start = time.perf_counter()
    g = gauss_kronrod(shape, eps)
    if not g["error"] >= 0:  # OCCT's sign of a failed integration
        raise SurfmodError("shape: BRepGProp's Gauss-Kronrod rule failed on it")
    return KronrodProps(g["volume"], g["area"], g["centroid"], g["inertia"], eps, g["error"],
                        time.perf_counter() - start)


def _kronrod_of_bytes(data: bytes, eps: float) -> KronrodProps:
    from ..occ.step import brep_from_bytes

    return kronrod_props(brep_from_bytes(data), eps)


def kronrod_props_within(shape, seconds: float, eps: float = 1e-10) -> KronrodProps:
    """:func:`kronrod_props` in a child process, given ``seconds`` to answer; ``SurfmodError``
    naming ``budget`` when it does not (the child is killed) or dies.

    >>> import build123d as bd
    >>> round(kronrod_props_within(bd.Box(1, 2, 3).wrapped, 60).volume, 12)
    6.0
    """
    from ..occ.step import brep_bytes

    if not seconds > 0:
        raise SurfmodError("budget: no time left for the Gauss-Kronrod reference")
    try:
        return child.call(_kronrod_of_bytes, (brep_bytes(shape), float(eps)), seconds, "the Gauss-Kronrod reference")
    except child.ChildFailure as exc:
        raise SurfmodError(f"budget: {exc}") from None


def judge(shape, solid, r, o, *, eps: float, density: float, occt, ambiguity, strays, say=print) -> int:
    """The verdict of ``surfmod mass`` on ``solid`` (read from the file's ``shape``), its
    lines passed to ``say`` as they come, and its exit status: 0 when surfmod's ``r`` and
    BRepGProp's ``o`` (at ``eps``, both at ``density``) agree within ``MASS_AGREEMENT_RTOL``, or when they differ
    and a reference (:func:`settle`) confirms surfmod; :data:`EXIT_DISAGREE` when it confirms
    BRepGProp, or cannot tell on a model whose edges close; :data:`EXIT_AMBIGUOUS` when it
    cannot tell and the model itself is ambiguous.  ``occt(eps)`` measures BRepGProp's side
    again at a finer ``eps``, ``ambiguity()`` is the model's boundary ambiguity (asked only
    when needed), ``strays`` the file's edges with their p-curves' strays
    (:func:`surfmod.readback.strays.edge_strays`); faces outside every solid are named, and
    their edges do not count."""
    from ..occ.solids import left_out_faces

    left = left_out_faces(shape)
    if left:  # an open shell beside the solids: measured it would be a guess, so it is named instead
        say(f"NOTE: {len(left)} face(s) outside every closed solid (open shells or loose faces) are left out, "
            f"they enclose no volume: faces {', '.join(map(str, left[:10]))}{' ...' if len(left) > 10 else ''}")
    limit = tolerances.MASS_AGREEMENT_RTOL
    diffs = relative_differences(r, o)
    say(f"BRepGProp (eps={eps:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items())
        + f" (limit {limit:g}; centroid relative to volume^(1/3), inertia to its largest entry)")
    off = {k: v for k, v in diffs.items() if not v <= limit}
    if off:
        # BRepGProp's adaptive eps bounds the volume's error; its first and second moments
        # converge more slowly (a cube and a cylinder: inertia 1.1e-6 off at eps 1e-9, 3.4e-8
        # at 1e-11, 8.2e-10 at 1e-13, towards surfmod's): judge everything at a finer eps
        fine = max(eps * 1e-4, 1e-14)
        o = occt(fine)
        diffs = relative_differences(r, o)
        say(f"BRepGProp (eps={fine:g}) relative differences: " + ", ".join(f"{k} {v:.2e}" for k, v in diffs.items()))
        off = {k: v for k, v in diffs.items() if not v <= limit}
    # measured on the file's shape, so edges and faces carry the file's numbers, as the
    # faces left out do; edges of those faces bound no volume and do not count
    outside = set(left)
    strays = sorted((e for e in strays if e.ambiguous and outside.isdisjoint(e.faces)),
                    key=lambda e: -max(e.stray, e.gap))
    named = ", ".join(f"edge {e.edge} of faces {'/'.join(map(str, e.faces))} ({max(e.stray, e.gap):.2e} > tol "
                      f"{e.tolerance:.1e})" for e in strays[:5]) + (" ..." if len(strays) > 5 else "")
    amb = None
    if strays:  # whatever the verdict: the digits below the strays are the file's, not the part's
        amb = ambiguity()
        say(f"NOTE: {len(strays)} edge(s) have p-curves straying beyond their own tolerance: {named}; the file's "
            f"edges leave its volume open by up to {amb:.2e} (relative): digits beyond that are the file's, not "
            "the part's")
    if not off:
        say(f"AGREE: volume, area, centroid and inertia all agree with BRepGProp within {limit:g}")
        return 0
    worst = max(off.values())
    side, line = settle(solid, r, o, sorted(off), limit, density)
    say(line)
    if side == "surfmod":
        return 0
    differ = f"{', '.join(off)} differ{'s' if len(off) == 1 else ''} from BRepGProp by up to {worst:.2e}"
    if side is None:
        amb = ambiguity() if amb is None else amb
        if strays or amb >= worst:
            say(f"AMBIGUOUS MODEL: {differ} (more than {limit:g}); the model's edges leave its volume open by up to "
                f"{amb:.2e} (relative) and {len(strays)} edge(s) have p-curves straying beyond their own tolerance"
                + (f": {named}" if strays else ""))
            return EXIT_AMBIGUOUS
        say(f"DISAGREEMENT: {differ}, more than the model's own ambiguity {amb:.2e}, and no edge strays beyond "
            "its tolerance")
        return EXIT_DISAGREE
    say(f"DISAGREEMENT: {differ}, and the reference confirms BRepGProp's")
    return EXIT_DISAGREE


def settle(solid, r, o, names, limit, density: float = 1.0):
    """``(side, line)``: which of surfmod ``r`` and BRepGProp ``o`` an independent reference
    confirms for the differing quantities ``names``: ``"surfmod"`` when surfmod is within
    ``limit`` of it and BRepGProp is not, by more than the reference's own error estimate;
    ``"occt"`` the other way round; ``None`` (with the reasons) when no reference can tell
    within :data:`REFERENCE_BUDGET` seconds.  The references, in turn until one tells:
    :func:`refined_props`, then :func:`kronrod_props_within` (for solids whose split is not
    exact); ``density`` scales the references' inertia as it scales theirs."""
    start = time.perf_counter()
    lines = []
    for reference in (_split_reference, _kronrod_reference):
        try:
            ref, how, errors = reference(solid, names, REFERENCE_BUDGET - (time.perf_counter() - start))
        except SurfmodError as exc:
            lines.append(f"REFERENCE SKIPPED: {exc}")
            continue
        side, line = _verdict(dataclasses.replace(ref, inertia=density * ref.inertia), r, o, names, limit, how, errors)
        lines.append(line)
        if side is not None:  # the lines of the references that could not tell come first
            return side, "\n".join(lines)
    return None, "\n".join(lines)


def _split_reference(solid, names, seconds):
    """``(reference, how it is named, its error per quantity)``: the faces split."""
    ref = refined_props(solid, budget=seconds)
    return ref, f"BRepGProp on the faces split {ref.splits} x {ref.splits}", ref.changes


def _kronrod_reference(solid, names, seconds):
    """The same for the Gauss-Kronrod rule: one error estimate for every quantity."""
    ref = kronrod_props_within(solid, seconds)
    return ref, "BRepGProp's Gauss-Kronrod rule", dict.fromkeys(names, ref.error)


def _verdict(ref, r, o, names, limit, how, errors):
    diffs = {"surfmod": relative_differences(r, ref), "occt": relative_differences(o, ref)}
    sides = set()
    for k in names:
        mine, theirs, est = diffs["surfmod"][k], diffs["occt"][k], errors[k]
        if mine + est <= limit < theirs - est:
            sides.add("surfmod")
        elif theirs + est <= limit < mine - est:
            sides.add("occt")
        else:
            sides.add(None)
    detail = ", ".join(f"{k}: surfmod {diffs['surfmod'][k]:.2e}, BRepGProp {diffs['occt'][k]:.2e} (its error "
                       f"{errors[k]:.1e})" for k in names)
    if sides == {"surfmod"}:
        return "surfmod", f"REFERENCE CONFIRMS SURFMOD: {how} agrees with surfmod, not with plain BRepGProp ({detail})"
    if sides == {"occt"}:
        return "occt", f"REFERENCE CONFIRMS BREPGPROP: {how} agrees with plain BRepGProp, not surfmod ({detail})"
    return None, f"REFERENCE UNDECIDED: {how} cannot tell the two apart ({detail})"
