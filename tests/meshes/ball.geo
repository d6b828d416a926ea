// A ball of radius 0.3 m centred at (0.5, 0.5, 0.5), for the tests of bodies made from a Gmsh
// mesh (tetrahedra, physical volume "ball", its skin "skin") and from an STL surface.
// gmsh -3 -format msh41 ball.geo -o ball.msh; gmsh -2 ball.geo -o ball.stl
SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.06;
Sphere(1) = {0.5, 0.5, 0.5, 0.3};
Physical Volume("ball") = {1};
Physical Surface("skin") = {1};
