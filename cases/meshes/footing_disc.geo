// A quarter of a circular footing, radius 0.5 m and 0.25 m thick, standing on the plane y = 1.5 m
// with its axis on the grid line x = z = 0 (the planes x = 0 and z = 0 are planes of symmetry), for
// cases/footing_stl_3d.toml: the STL file of its closed surface, as a CAD program would give it.
// gmsh -2 footing_disc.geo -o footing_disc.stl
SetFactory("OpenCASCADE");
Mesh.CharacteristicLengthMax = 0.04;
Cylinder(1) = {0, 1.5, 0, 0, 0.25, 0, 0.5, Pi / 2};
