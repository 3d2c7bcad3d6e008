// Mode-I plate (issue 51): 40 x 40 mm with a slot 12 mm long and 1 mm
// wide cut in from the middle of its left edge; the grips are the top
// and bottom edges.  Unstructured triangles; the mesh size is set by
// the loader (skfem_pg.meshing.from_geo(..., size=h)).
h = 10.0;
Point(1) = {0, 0, 0, h};
Point(2) = {40, 0, 0, h};
Point(3) = {40, 40, 0, h};
Point(4) = {0, 40, 0, h};
Point(5) = {0, 20.5, 0, h};
Point(6) = {12, 20.5, 0, h};
Point(7) = {12, 19.5, 0, h};
Point(8) = {0, 19.5, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8};
Plane Surface(1) = {1};
Physical Curve("bottom") = {1};
Physical Curve("top") = {3};
Physical Curve("slot") = {5, 6, 7};
Physical Surface("plate") = {1};
