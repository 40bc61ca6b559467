"""Exchange files: STEP, STL (and later DXF, SVG, G-code); every write is atomic."""
