// A quarter of a thick ring, inner radius 0.3 m, outer 0.9 m, in the plane x ≥ 0, y ≥ 0: in axial
// symmetry about y the meridian section of half a thick spherical shell (triangles, physical
// surface "shell").
// gmsh -2 -format msh41 shell_quarter_2d.geo -o shell_quarter_2d.msh
SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.025;
Disk(1) = {0, 0, 0, 0.9};
Disk(2) = {0, 0, 0, 0.3};
Rectangle(3) = {0, 0, 0, 1, 1};
ring() = BooleanDifference{ Surface{1}; Delete; }{ Surface{2}; Delete; };
quarter() = BooleanIntersection{ Surface{ring()}; Delete; }{ Surface{3}; Delete; };
Physical Surface("shell") = {quarter()};
