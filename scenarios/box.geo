// The parallelepiped of the seed paper's section 3.1: 30 x 15 x 15 cm, in metres.
// Regenerate box.msh with:  gmsh -3 -format msh22 -o box.msh box.geo
// (Gmsh 4.8.4 from Debian; the .msh is committed so that builds need no Gmsh.)
// The mesh size gives about 1.3k tetrahedra: one uniform refinement (each tetrahedron into
// eight) then gives the ~10k-tetrahedron box of the benchmarks.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.30, 0.15, 0.15};
Mesh.CharacteristicLengthMin = 0.03;
Mesh.CharacteristicLengthMax = 0.03;
Mesh.Algorithm3D = 1;        // Delaunay
Mesh.Optimize = 1;
Mesh.RandomSeed = 1;
Physical Volume("organ", 1) = {1};
