// A plane slope on a layer of rock, for the tests of bodies made from a Gmsh mesh:
// the rock's quadrangles (physical surface "rock") under the slope's triangles ("soil"), with
// its base ("base", y = 0) and crest ("crest") as physical curves.
// gmsh -2 -format msh41 layers_2d.geo -o layers_2d.msh
h = 0.25;
Point(1) = {0, 0, 0, h};  Point(2) = {4, 0, 0, h};  Point(3) = {4, 0.5, 0, h};
Point(4) = {0, 0.5, 0, h}; Point(5) = {4, 1.0, 0, h}; Point(6) = {2.6, 1.0, 0, h};
Point(7) = {1.4, 1.9, 0, h}; Point(8) = {0, 1.9, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 7}; Line(8) = {7, 8}; Line(9) = {8, 4};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7, 8, 9}; Plane Surface(2) = {2};
Transfinite Curve{1, 3} = 17; Transfinite Curve{2, 4} = 3;
Transfinite Surface{1}; Recombine Surface{1};
Physical Surface("rock") = {1};
Physical Surface("soil") = {2};
Physical Curve("crest") = {6, 7, 8};
Physical Curve("base") = {1};
