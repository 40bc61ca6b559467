"""Meshes of surfaces: the lecture's m x n grid mesh, adaptive tessellation, iso-curves."""
