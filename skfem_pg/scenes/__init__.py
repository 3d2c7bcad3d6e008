"""Scenes: one problem solved by any formulation name (``scene``), cached
FE overkill references (``reference``), node sets from the ``.geo``
sources of the repository's ``meshes/`` (``meshing``), VTU output
(``io``) and result pages (``reporting``)."""
from .scene import Scene, Result, inside, centroid_tree

__all__ = ["Scene", "Result", "inside",
           "centroid_tree"]
