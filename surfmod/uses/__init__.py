"""The uses of surface models: mass properties, interference, sections, FE meshes, NC paths."""
