// A plane-strain steel plate with two circular cut-outs (thesis 8.1, whose
// geometry is given only in its Fig. 8.1(a); the dimensions here are
// chosen): 20 x 40 mm, holes of radius 3 mm at (7, 17) and (13, 23): the
// ligament between them (2.5 mm) runs at 45 degrees through the centre
// and is narrower than the two outer bridges (4 mm) to the plate's edges.
SetFactory("OpenCASCADE");
h = 1.0;
W = 20; H = 40; R = 3;
Point(1) = {0, 0, 0, h};
Point(2) = {W, 0, 0, h};
Point(3) = {W, H, 0, h};
Point(4) = {0, H, 0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Circle(5) = {7, 17, 0, R, 0, 2*Pi};
Curve Loop(2) = {5};
Circle(6) = {13, 23, 0, R, 0, 2*Pi};
Curve Loop(3) = {6};
Plane Surface(1) = {1, 2, 3};
Physical Curve("bottom") = {1};
Physical Curve("right") = {2};
Physical Curve("top") = {3};
Physical Curve("left") = {4};
Physical Curve("holes") = {5, 6};
Physical Surface("domain") = {1};
