"""Exchange files: STEP, IGES, STL, DXF and SVG; every write is atomic."""
