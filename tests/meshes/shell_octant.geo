// An eighth of a thick spherical shell, inner radius 0.3 m, outer 0.9 m, centred at the origin, for
// the Lamé sphere in three dimensions: tetrahedra (physical volume "shell") and the triangles of
// its inner surface ("cavity"), which the internal pressure loads.
// gmsh -3 -format msh41 shell_octant.geo -o shell_octant.msh
SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.05;
Sphere(1) = {0, 0, 0, 0.9};
Sphere(2) = {0, 0, 0, 0.3};
Box(3) = {0, 0, 0, 1, 1, 1};
shell() = BooleanDifference{ Volume{1}; Delete; }{ Volume{2}; Delete; };
octant() = BooleanIntersection{ Volume{shell()}; Delete; }{ Volume{3}; Delete; };
Physical Volume("shell") = {octant()};
e = 1e-6;
Physical Surface("cavity") = {Surface In BoundingBox{-e, -e, -e, 0.3 + e, 0.3 + e, 0.3 + e}};
