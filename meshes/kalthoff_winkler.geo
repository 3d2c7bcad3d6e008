// Kalthoff-Winkler plate (issue 51): 100 x 200 mm, two notches 50 mm
// long and 1 mm wide cut in from the hit edge (x = 0) at y = +-25 mm
// (centre lines).  Unstructured triangles; the mesh size is set by the
// loader (skfem_pg.meshing.from_geo(..., size=h)).
h = 10.0;
w = 0.5;  // half the notch width
Point(1) = {0, -100, 0, h};
Point(2) = {100, -100, 0, h};
Point(3) = {100, 100, 0, h};
Point(4) = {0, 100, 0, h};
Point(5) = {0, 25 + w, 0, h};
Point(6) = {50, 25 + w, 0, h};
Point(7) = {50, 25 - w, 0, h};
Point(8) = {0, 25 - w, 0, h};
Point(9) = {0, -25 + w, 0, h};
Point(10) = {50, -25 + w, 0, h};
Point(11) = {50, -25 - w, 0, h};
Point(12) = {0, -25 - w, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 6};
Line(6) = {6, 7};
Line(7) = {7, 8};
Line(8) = {8, 9};
Line(9) = {9, 10};
Line(10) = {10, 11};
Line(11) = {11, 12};
Line(12) = {12, 1};
Curve Loop(1) = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
Plane Surface(1) = {1};
Physical Curve("hit") = {8};
Physical Curve("notches") = {5, 6, 7, 9, 10, 11};
Physical Surface("plate") = {1};
