"""Scenes: one problem solved by any formulation name (``scene``), cached
FE overkill references (``reference``), node sets from the ``.geo``
sources of the repository's ``meshes/`` (``meshing``).  VTU output is
:mod:`skfem_pg.io`."""
from .scene import Scene, Result, Setup, inside, centroid_tree

__all__ = ["Scene", "Result", "Setup", "inside",
           "centroid_tree"]
