// The box of box.geo (30 x 15 x 15 cm, in metres) at a coarser mesh size: about 400
// tetrahedra, for scenarios that run many whole filter runs (box_diagnose.json: `diagnose`
// runs one per candidate effect).
// Regenerate box_coarse.msh with:  gmsh -3 -format msh22 -o box_coarse.msh box_coarse.geo
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.30, 0.15, 0.15};
Mesh.CharacteristicLengthMin = 0.05;
Mesh.CharacteristicLengthMax = 0.05;
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;
Mesh.RandomSeed = 1;
Physical Volume("organ", 1) = {1};
