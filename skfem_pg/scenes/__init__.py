"""Scenes: one problem solved by any formulation name (``scene``), cached
FE overkill references (``reference``), node sets and ``.geo`` sources
(``meshing``, ``meshes/``), VTU output (``io``) and result pages
(``reporting``)."""
from .scene import Scene, Result, FE_METHODS, INTORDER, inside, centroid_tree

__all__ = ["Scene", "Result", "FE_METHODS", "INTORDER", "inside",
           "centroid_tree"]
