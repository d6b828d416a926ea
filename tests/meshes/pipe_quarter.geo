// A quarter of a thick cylinder, inner radius 0.3 m, outer 0.9 m, axis along z from z = 0 to 0.4 m,
// for the Lamé cylinder in three dimensions: prisms and hexahedra swept along z (physical volume
// "pipe") and the quadrangles of its inner face ("bore"), which the internal pressure loads.
// gmsh -3 -format msh41 pipe_quarter.geo -o pipe_quarter.msh
lc = 0.05;
Point(1) = {0, 0, 0, lc}; Point(2) = {0.3, 0, 0, lc}; Point(3) = {0.9, 0, 0, lc};
Point(4) = {0, 0.9, 0, lc}; Point(5) = {0, 0.3, 0, lc};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Curve{1, 3} = 13; Transfinite Curve{2} = 37; Transfinite Curve{4} = 13;
out[] = Extrude {0, 0, 0.4} { Surface{1}; Layers{8}; Recombine; };
// out[]: the top, the volume, then the sides swept from curves 1, 2, 3 and 4.
Physical Volume("pipe") = {out[1]};
Physical Surface("bore") = {out[5]};
