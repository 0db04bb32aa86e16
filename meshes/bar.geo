// Rectangular bar: the box from (x0, y0, z0) to (x0 + lx, y0 + ly, z0 + lz), in metres.
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets
// them from the scene's [mesh] table with `-setnumber`. The mesh is structured
// (extruded layers): hexahedra when `hexahedra = 1`, otherwise every hexahedral
// brick is split into tetrahedra.
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  lx = {0.01, Min 1e-9, Name "Parameters/2Size/lx"},
  ly = {0.01, Min 1e-9, Name "Parameters/2Size/ly"},
  lz = {0.1, Min 1e-9, Name "Parameters/2Size/lz"},
  h = {0.002, Min 1e-9, Name "Parameters/3Mesh/element size"},
  hexahedra = {1, Choices{0="tetrahedra", 1="hexahedra"}, Name "Parameters/3Mesh/cells"}
];

// Number of element layers along each side: the smallest count with layers <= h.
nx = Ceil(lx / h - 1e-9);
ny = Ceil(ly / h - 1e-9);
nz = Ceil(lz / h - 1e-9);

Point(1) = {x0, y0, z0, h};
If (hexahedra)
  ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; Recombine; };
  ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; Recombine; };
  ez[] = Extrude {0, 0, lz} { Surface{ey[1]}; Layers{nz}; Recombine; };
Else
  ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; };
  ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; };
  ez[] = Extrude {0, 0, lz} { Surface{ey[1]}; Layers{nz}; };
EndIf

// Named groups a scene can refer to (wall secondaries, clamps).
Physical Surface("bottom") = {ey[1]};                 // z = z0
Physical Surface("top") = {ez[0]};                    // z = z0 + lz
Physical Surface("sides") = {ez[2], ez[3], ez[4], ez[5]};
Physical Volume("body") = {ez[1]};
