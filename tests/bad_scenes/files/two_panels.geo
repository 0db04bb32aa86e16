// Two square panels meeting at a right angle along the y axis, 10 mm, as shells: the
// physical surfaces "floor" (z = 0) and "wall" (x = 0) are two parts; the far edge of the
// floor is the physical curve "free_edge".
h = 0.005;
Point(1) = {0, 0, 0, h};
Point(2) = {0.01, 0, 0, h};
Point(3) = {0.01, 0.01, 0, h};
Point(4) = {0, 0.01, 0, h};
Point(5) = {0, 0, 0.01, h};
Point(6) = {0, 0.01, 0.01, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Line(5) = {1, 5};
Line(6) = {5, 6};
Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 4};
Plane Surface(2) = {2};
Transfinite Surface{1, 2};
Recombine Surface{1, 2};
Physical Surface("floor") = {1};
Physical Surface("wall") = {2};
Physical Curve("free_edge") = {2};
