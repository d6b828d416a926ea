// A road embankment ending on a foundation, for cases/embankment_3d.toml: half of it (the plane
// x = 0 is its centreline). The foundation is the box 8 × 2 × 8 m (physical volume "foundation");
// the fill, 1 m high, runs along z from the plane z = 0 (a plane of symmetry too) and ends in a
// 2:1 slope: a crest 2 m wide (half-width) to z = 4 m, side slopes of 2:1 down to the base's
// half-width of 4 m, the end slope down to z = 6 m ("fill"). Both are meshed with tetrahedra of
// about 0.4 m; they need not share nodes (the material points only sample the cells).
// gmsh -3 -format msh41 embankment_3d.geo -o embankment_3d.msh
lc = 0.4;
// The foundation.
Point(1) = {0, 0, 0, lc}; Point(2) = {8, 0, 0, lc}; Point(3) = {8, 2, 0, lc}; Point(4) = {0, 2, 0, lc};
Point(5) = {0, 0, 8, lc}; Point(6) = {8, 0, 8, lc}; Point(7) = {8, 2, 8, lc}; Point(8) = {0, 2, 8, lc};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {5, 6}; Line(6) = {6, 7}; Line(7) = {7, 8}; Line(8) = {8, 5};
Line(9) = {1, 5}; Line(10) = {2, 6}; Line(11) = {3, 7}; Line(12) = {4, 8};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {5, 6, 7, 8}; Plane Surface(2) = {2};
Curve Loop(3) = {1, 10, -5, -9}; Plane Surface(3) = {3};
Curve Loop(4) = {2, 11, -6, -10}; Plane Surface(4) = {4};
Curve Loop(5) = {3, 12, -7, -11}; Plane Surface(5) = {5};
Curve Loop(6) = {4, 9, -8, -12}; Plane Surface(6) = {6};
Surface Loop(1) = {1, 2, 3, 4, 5, 6}; Volume(1) = {1};
// The fill: base A B C F on y = 2, crest H E D G on y = 3.
Point(11) = {0, 2, 0, lc}; Point(12) = {4, 2, 0, lc}; Point(13) = {4, 2, 6, lc}; Point(14) = {0, 2, 6, lc};
Point(15) = {0, 3, 0, lc}; Point(16) = {2, 3, 0, lc}; Point(17) = {2, 3, 4, lc}; Point(18) = {0, 3, 4, lc};
Line(21) = {11, 12}; Line(22) = {12, 13}; Line(23) = {13, 14}; Line(24) = {14, 11};
Line(25) = {15, 16}; Line(26) = {16, 17}; Line(27) = {17, 18}; Line(28) = {18, 15};
Line(29) = {11, 15}; Line(30) = {12, 16}; Line(31) = {13, 17}; Line(32) = {14, 18};
Curve Loop(11) = {21, 22, 23, 24}; Plane Surface(11) = {11};     // base
Curve Loop(12) = {25, 26, 27, 28}; Plane Surface(12) = {12};     // crest
Curve Loop(13) = {21, 30, -25, -29}; Plane Surface(13) = {13};   // z = 0
Curve Loop(14) = {22, 31, -26, -30}; Plane Surface(14) = {14};   // side slope
Curve Loop(15) = {23, 32, -27, -31}; Plane Surface(15) = {15};   // end slope
Curve Loop(16) = {24, 29, -28, -32}; Plane Surface(16) = {16};   // x = 0
Surface Loop(2) = {11, 12, 13, 14, 15, 16}; Volume(2) = {2};
Physical Volume("foundation") = {1};
Physical Volume("fill") = {2};
