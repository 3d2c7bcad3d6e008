// An angle bracket (benchmarks/factor_reuse.py): a base plate 40 x 30 x 5
// with two bolt holes (radius 3.5 at x = 10, 30, y = 19), an upright
// 40 x 5 x 35 with a hole (radius 6 at x = 20, z = 22); unstructured
// tetrahedra.  No physical surfaces: the benchmark selects the bolt holes
// and the upright's top face (z = 35) by position.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 40, 30, 5};
Box(2) = {0, 0, 0, 40, 5, 35};
Cylinder(3) = {10, 19, -1, 0, 0, 7, 3.5};
Cylinder(4) = {30, 19, -1, 0, 0, 7, 3.5};
Cylinder(5) = {20, -1, 22, 0, 7, 0, 6};
BooleanUnion(6) = {Volume{1}; Delete;}{Volume{2}; Delete;};
BooleanDifference(7) = {Volume{6}; Delete;}{Volume{3, 4, 5}; Delete;};
Physical Volume("bracket") = {7};
