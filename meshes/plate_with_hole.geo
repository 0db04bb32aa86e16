// Plate with a hole: the plate from (x0, y0, z0) to (x0 + lx, y0 + ly, z0 + thickness), in
// metres, thin along its own z, with a circular through-hole of radius hole_radius whose
// centre is (hole_dx, hole_dy) away from the plate's centre (0, 0: centred).
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets
// them from the scene's [mesh] table with `-setnumber` (and turns the plate so that its own
// z axis lies along the scene's axis afterwards). The section is meshed unstructured at
// size h (quadrangles recombined by Blossom when `hexahedra = 1`, triangles otherwise) and
// swept through the thickness in `layers` equal layers (0: the fewest layers at most h
// thick): hexahedra, or prisms split into tetrahedra.
//
// Refinement (refine_size > 0, see refine.geo): the in-plane size falls to refine_size at
// (refine_x, refine_y) and grows back to h over refine_radius; refine_z is not used (the
// layers through the thickness stay uniform).
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
  hole_radius = {0.02, Min 1e-9, Name "Parameters/2Size/hole radius"},
  hole_dx = {0, Name "Parameters/2Size/hole centre x - plate centre x"},
  hole_dy = {0, Name "Parameters/2Size/hole centre y - plate centre y"},
  h = {0.005, Min 1e-9, Name "Parameters/3Mesh/element size"},
  layers = {0, Min 0, Step 1, Name "Parameters/3Mesh/layers through the thickness (0: auto)"},
  hexahedra = {1, Choices{0="tetrahedra", 1="hexahedra"}, Name "Parameters/3Mesh/cells"},
  refine_size = {0, Min 0, Name "Parameters/4Refinement/size at the point (0: none)"},
  refine_radius = {0.02, Min 1e-9, Name "Parameters/4Refinement/radius"},
  refine_x = {0.07, Name "Parameters/4Refinement/x"},
  refine_y = {0.05, Name "Parameters/4Refinement/y"},
  refine_z = {0, Name "Parameters/4Refinement/z (not used)"},
  bottom_layer = {0, Min 0, Name "Parameters/5Regions/bottom layer (0: none)"},
  top_layer = {0, Min 0, Name "Parameters/5Regions/top layer (0: none)"}
];

cx = x0 + lx / 2 + hole_dx;
cy = y0 + ly / 2 + hole_dy;

Point(1) = {x0, y0, z0, h};
Point(2) = {x0 + lx, y0, z0, h};
Point(3) = {x0 + lx, y0 + ly, z0, h};
Point(4) = {x0, y0 + ly, z0, h};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Point(5) = {cx, cy, z0, h};
Point(6) = {cx + hole_radius, cy, z0, h};
Point(7) = {cx, cy + hole_radius, z0, h};
Point(8) = {cx - hole_radius, cy, z0, h};
Point(9) = {cx, cy - hole_radius, z0, h};
Circle(5) = {6, 5, 7};
Circle(6) = {7, 5, 8};
Circle(7) = {8, 5, 9};
Circle(8) = {9, 5, 6};
Curve Loop(2) = {5, 6, 7, 8};
Plane Surface(1) = {1, 2};

Include "refine.geo";
Include "sweep.geo";

If (hexahedra)
  Mesh.Algorithm = 6;
  Mesh.RecombinationAlgorithm = 1;
  Recombine Surface{1};
EndIf
section = 1;
sweep_length = thickness;
first_length = bottom_layer;
last_length = top_layer;
sweep_layers = layers;
sweep_graded = 0;
Call Sweep;

// Named groups a scene can refer to (wall secondaries, clamps, parts). Extrude lists the
// lateral faces of each region in the order of the section's boundary curves: the outer
// loop (4), then the hole (4).
Physical Surface("bottom") = {1};                     // z = z0
Physical Surface("top") = {sweep_top};                // z = z0 + thickness
sides[] = {};
hole[] = {};
For region In {0 : #sweep_volumes[] - 1}
  sides[] += sweep_lateral[{8 * region : 8 * region + 3}];
  hole[] += sweep_lateral[{8 * region + 4 : 8 * region + 7}];
EndFor
Physical Surface("sides") = {sides[]};
Physical Surface("hole") = {hole[]};
Call PlateRegions;
