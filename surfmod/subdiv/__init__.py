"""Subdivision surfaces: Catmull–Clark, Loop, limit masks and limit-surface patches."""
