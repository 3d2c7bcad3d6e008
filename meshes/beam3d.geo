// Cantilever 20 x 2 x 2, unstructured tetrahedra (benchmarks/recipes_3d.py):
// clamped at x = 0, tip load in z on x = 20.
SetFactory("OpenCASCADE");
h = 10;  // the size comes from from_geo(size=)
Box(1) = {0, 0, 0, 20, 2, 2};
MeshSize{ PointsOf{ Volume{1}; } } = h;
