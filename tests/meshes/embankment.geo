// An embankment on a foundation, extruded along z, for the tests of bodies made from a Gmsh mesh:
// the foundation's prisms (physical volume "foundation") under the fill's hexahedra ("fill"),
// with the foundation's base (y = 0) as the physical surface "bottom".
// gmsh -3 -format msh41 embankment.geo -o embankment.msh
h = 0.5;
Point(1) = {0, 0, 0, h}; Point(2) = {6, 0, 0, h}; Point(3) = {6, 1, 0, h}; Point(4) = {0, 1, 0, h};
Point(5) = {1, 1, 0, h}; Point(6) = {5, 1, 0, h}; Point(7) = {3.5, 2, 0, h}; Point(8) = {2.5, 2, 0, h};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 6}; Line(4) = {6, 5}; Line(5) = {5, 4}; Line(6) = {4, 1};
Line(7) = {6, 7}; Line(8) = {7, 8}; Line(9) = {8, 5};
Curve Loop(1) = {1, 2, 3, 4, 5, 6}; Plane Surface(1) = {1};
Curve Loop(2) = {-4, 7, 8, 9}; Plane Surface(2) = {2};
Transfinite Curve{4, 8} = 5; Transfinite Curve{7, 9} = 3;
Transfinite Surface{2}; Recombine Surface{2};
ground[] = Extrude {0, 0, 2} { Surface{1}; Layers{4}; Recombine; };
fill[] = Extrude {0, 0, 2} { Surface{2}; Layers{4}; Recombine; };
Physical Volume("foundation") = {ground[1]};
Physical Volume("fill") = {fill[1]};
Physical Surface("bottom") = {ground[2]};
