"""Evaluator conformance: any evaluator of B-spline, NURBS and Bézier surfaces and curves
held against OCCT and a 40-digit reference (``sm.conformance``, ``surfmod conformance``).

The cases (:mod:`~surfmod.conform.cases`), the adapters that call an evaluator
(:mod:`~surfmod.conform.adapters`), the cached reference
(:mod:`~surfmod.conform.reference`) and the table (:mod:`~surfmod.conform.table`).
"""

from __future__ import annotations

from .table import Conformance, conformance

__all__ = ["Conformance", "conformance"]
