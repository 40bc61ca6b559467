"""Machining: cutters, drop-cutter and exact tool paths, their checks, and G-code output."""
