// A block (a physical volume) and, apart from it, a sheet (a physical surface): shells
// beside solids in one mesh, which a scene does not mix.
SetFactory("OpenCASCADE");
Box(1) = {0, 0, 0, 0.01, 0.01, 0.01};
Rectangle(100) = {0, 0, 0.02, 0.01, 0.01};
Physical Volume("block") = {1};
Physical Surface("sheet") = {100};
