// A box whose second physical volume names no volume: a region without cells.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.01, 0.01, 0.02};
Mesh.MeshSizeMax = 0.005;
Physical Volume("body") = {1};
Physical Volume("empty") = {};
