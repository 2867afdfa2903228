// The box of box.geo (30 x 15 x 15 cm, in metres) meshed finer, for box_large.json.
// Regenerate box_fine.msh with:  gmsh -3 -format msh22 -o box_fine.msh box_fine.geo
// (Gmsh 4.8.4 from Debian; the .msh is committed so that builds need no Gmsh.)
// The mesh size 0.0135 m gives 14655 tetrahedra; box_large.json refines it once (x8) to
// 117240, the 100k-element box for the GPU back ends.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.30, 0.15, 0.15};
Mesh.CharacteristicLengthMin = 0.0135;
Mesh.CharacteristicLengthMax = 0.0135;
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;
Mesh.RandomSeed = 1;
Physical Volume("organ", 1) = {1};
