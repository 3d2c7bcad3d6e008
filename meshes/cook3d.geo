// 3-D Cook's membrane (thesis Fig. 7.3): the 2-D outline extruded by a
// thickness of 10 in z, unstructured tetrahedra.  Clamped face "left"
// (x = 0), loaded face "right" (x = 48).
SetFactory("OpenCASCADE");
h = 8;
Point(1) = { 0,  0, 0, h};
Point(2) = {48, 44, 0, h};
Point(3) = {48, 60, 0, h};
Point(4) = { 0, 44, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
out[] = Extrude {0, 0, 10} { Surface{1}; };
Physical Surface("left") = {Surface In BoundingBox{-1, -1, -1, 1, 61, 11}};
Physical Surface("right") = {Surface In BoundingBox{47, 43, -1, 49, 61, 11}};
Physical Volume("domain") = {out[1]};
