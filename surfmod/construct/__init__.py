"""Constructors: each lecture entity -> a surfmod Surface (or Curve)."""
