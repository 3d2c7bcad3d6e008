// Plate 10 x 10 x 2 with a through hole of radius 2 at its centre,
// unstructured tetrahedra (benchmarks/recipes_3d.py): clamped at x = 0,
// pulled in x on x = 10.
SetFactory("OpenCASCADE");
h = 10;  // the size comes from from_geo(size=)
Box(1) = {0, 0, 0, 10, 10, 2};
Cylinder(2) = {5, 5, -1, 0, 0, 4, 2};
BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; }
MeshSize{ PointsOf{ Volume{1}; } } = h;
