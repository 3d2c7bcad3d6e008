"""The gmsh sources (``.geo``) of the package's node sets: Cook's membrane
in 2-D and 3-D, the unit square and cube, a 3-D cantilever, a plate with
a hole, and the fracture plates: two holes, a slot (mode I) and
Kalthoff–Winkler's two notches.  This directory is the one copy; the
wheel ships it as the data package ``skfem_pg.meshes`` (``pyproject.toml``,
``package-dir``), and :func:`skfem_pg.meshing.geo_path` finds a file in
either place."""
