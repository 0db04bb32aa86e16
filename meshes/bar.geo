// Rectangular bar: the box from (x0, y0, z0) to (x0 + lx, y0 + ly, z0 + lz), in metres.
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets
// them from the scene's [mesh] table with `-setnumber`. The mesh is structured
// (extruded layers): hexahedra when `hexahedra = 1`, otherwise every hexahedral
// brick is split into tetrahedra.
//
// Refinement (refine_size > 0, see refine.geo) needs an unstructured section: the
// rectangle is then meshed with the size falling to refine_size at (refine_x, refine_y)
// and growing back to h over refine_radius (quadrangles recombined by Blossom for
// hexahedra, triangles otherwise), and swept along z in layers graded by the same law
// around refine_z.
//
// Regions (physical volumes): "body", and with front > 0 the first `front` metres from
// z0 as the volume "front" (a striker's nose, a bimetal bar's first metal; sweep.geo).
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  lx = {0.01, Min 1e-9, Name "Parameters/2Size/lx"},
  ly = {0.01, Min 1e-9, Name "Parameters/2Size/ly"},
  lz = {0.1, Min 1e-9, Name "Parameters/2Size/lz"},
  h = {0.002, Min 1e-9, Name "Parameters/3Mesh/element size"},
  hexahedra = {1, Choices{0="tetrahedra", 1="hexahedra"}, Name "Parameters/3Mesh/cells"},
  refine_size = {0, Min 0, Name "Parameters/4Refinement/size at the point (0: none)"},
  refine_radius = {0.008, Min 1e-9, Name "Parameters/4Refinement/radius"},
  refine_x = {0.005, Name "Parameters/4Refinement/x"},
  refine_y = {0.005, Name "Parameters/4Refinement/y"},
  refine_z = {0.05, Name "Parameters/4Refinement/z"},
  front = {0, Min 0, Name "Parameters/5Regions/front length (0: none)"}
];

Include "refine.geo";
Include "sweep.geo";

If (refine_size > 0)
  Point(1) = {x0, y0, z0, h};
  Point(2) = {x0 + lx, y0, z0, h};
  Point(3) = {x0 + lx, y0 + ly, z0, h};
  Point(4) = {x0, y0 + ly, z0, h};
  Line(1) = {1, 2};
  Line(2) = {2, 3};
  Line(3) = {3, 4};
  Line(4) = {4, 1};
  Curve Loop(1) = {1, 2, 3, 4};
  Plane Surface(1) = {1};
  section = 1;
  If (hexahedra)
    Mesh.Algorithm = 6;
    Mesh.RecombinationAlgorithm = 1;
    Recombine Surface{1};
  EndIf
Else
  // Number of element layers along each side: the smallest count with layers <= h.
  nx = Ceil(lx / h - 1e-9);
  ny = Ceil(ly / h - 1e-9);
  Point(1) = {x0, y0, z0, h};
  If (hexahedra)
    ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; Recombine; };
    ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; Recombine; };
  Else
    ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; };
    ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; };
  EndIf
  section = ey[1];
EndIf
sweep_length = lz;
first_length = front;
last_length = 0;
sweep_layers = 0;
sweep_graded = 1;
Call Sweep;

// Named groups a scene can refer to (wall secondaries, clamps, parts).
Physical Surface("bottom") = {section};               // z = z0
Physical Surface("top") = {sweep_top};                // z = z0 + lz
Physical Surface("sides") = {sweep_lateral[]};
If (front > 0)
  Physical Volume("front") = {sweep_volumes[0]};
  Physical Volume("body") = {sweep_volumes[1]};
Else
  Physical Volume("body") = {sweep_volumes[0]};
EndIf
