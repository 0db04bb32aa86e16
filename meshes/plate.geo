// Plate: the box from (x0, y0, z0) to (x0 + lx, y0 + ly, z0 + thickness), in metres, thin
// along its own z.
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets
// them from the scene's [mesh] table with `-setnumber` (and turns the plate so that its own
// z axis lies along the scene's axis afterwards). `layers` elements through the thickness
// (0: the fewest layers at most h thick). Without refinement the mesh is structured like
// bar.geo: in-plane squares of side at most h (hexahedra, or each brick split into
// tetrahedra). With refinement (refine_size > 0, see refine.geo) the rectangle is meshed
// unstructured with the size falling to refine_size at (refine_x, refine_y) and growing back
// to h over refine_radius (quadrangles recombined by Blossom for hexahedra), then swept
// through the thickness in `layers` equal layers; refine_z is not used (the layers through
// the thickness stay uniform).
//
// Regions (physical volumes): "body", and with bottom_layer > 0 or top_layer > 0 the
// layers of those thicknesses at z0 and at the top as the volumes "bottom_layer" and
// "top_layer" (a pad, the skins of a sandwich; sweep.geo): `layers` are then shared among
// the regions in proportion to their thicknesses (at least one each).
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0 (lowest corner)"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  lx = {0.1, Min 1e-9, Name "Parameters/2Size/lx"},
  ly = {0.1, Min 1e-9, Name "Parameters/2Size/ly"},
  thickness = {0.002, Min 1e-9, Name "Parameters/2Size/thickness"},
  h = {0.005, Min 1e-9, Name "Parameters/3Mesh/element size"},
  layers = {0, Min 0, Step 1, Name "Parameters/3Mesh/layers through the thickness (0: auto)"},
  hexahedra = {1, Choices{0="tetrahedra", 1="hexahedra"}, Name "Parameters/3Mesh/cells"},
  refine_size = {0, Min 0, Name "Parameters/4Refinement/size at the point (0: none)"},
  refine_radius = {0.02, Min 1e-9, Name "Parameters/4Refinement/radius"},
  refine_x = {0.05, Name "Parameters/4Refinement/x"},
  refine_y = {0.05, Name "Parameters/4Refinement/y"},
  refine_z = {0, Name "Parameters/4Refinement/z (not used)"},
  bottom_layer = {0, Min 0, Name "Parameters/5Regions/bottom layer (0: none)"},
  top_layer = {0, Min 0, Name "Parameters/5Regions/top layer (0: none)"}
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
  // Structured: extruded points and lines, like bar.geo.
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

sweep_length = thickness;
first_length = bottom_layer;
last_length = top_layer;
sweep_layers = layers;
sweep_graded = 0;
Call Sweep;

// Named groups a scene can refer to (wall secondaries, clamps, parts).
Physical Surface("bottom") = {section};               // z = z0
Physical Surface("top") = {sweep_top};                // z = z0 + thickness
Physical Surface("sides") = {sweep_lateral[]};
Call PlateRegions;
