"""Surface manipulation: trimming, intersection, projection and shadows (NumPy first,
cross-checked against OCCT in the tests)."""
