// Round bar: the cylinder of radius `radius` (m) whose axis runs from (x0, y0, z0) (the
// centre of its bottom face) to (x0, y0, z0 + length).
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets
// them from the scene's [mesh] table with `-setnumber` (and turns the bar onto its axis
// afterwards). The disc section is meshed at size h (quadrangles recombined by Blossom
// when `hexahedra = 1`, triangles otherwise) and swept along z in layers at most h thick:
// hexahedra, or prisms split into tetrahedra.
//
// Refinement (refine_size > 0, see refine.geo): the size falls to refine_size at the point
// (refine_x, refine_y, refine_z) and grows back to h over refine_radius (m), in the section
// and along the axis.
//
// Regions (physical volumes): "body", and with front > 0 the first `front` metres from
// z0 as the volume "front" (a rod's nose of another metal; sweep.geo).
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0 (centre of the bottom face)"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  radius = {0.005, Min 1e-9, Name "Parameters/2Size/radius"},
  length = {0.1, Min 1e-9, Name "Parameters/2Size/length"},
  h = {0.002, Min 1e-9, Name "Parameters/3Mesh/element size"},
  hexahedra = {1, Choices{0="tetrahedra", 1="hexahedra"}, Name "Parameters/3Mesh/cells"},
  refine_size = {0, Min 0, Name "Parameters/4Refinement/size at the point (0: none)"},
  refine_radius = {0.008, Min 1e-9, Name "Parameters/4Refinement/radius"},
  refine_x = {0.005, Name "Parameters/4Refinement/x"},
  refine_y = {0, Name "Parameters/4Refinement/y"},
  refine_z = {0.05, Name "Parameters/4Refinement/z"},
  front = {0, Min 0, Name "Parameters/5Regions/front length (0: none)"}
];

Point(1) = {x0, y0, z0, h};
Point(2) = {x0 + radius, y0, z0, h};
Point(3) = {x0, y0 + radius, z0, h};
Point(4) = {x0 - radius, y0, z0, h};
Point(5) = {x0, y0 - radius, z0, h};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

Include "refine.geo";
Include "sweep.geo";

If (hexahedra)
  // Frontal-Delaunay, then Blossom recombination (its perfect matching leaves no triangle
  // here; rwall_fem refuses a mesh of mixed cells if one ever does).
  Mesh.Algorithm = 6;
  Mesh.RecombinationAlgorithm = 1;
  Recombine Surface{1};
EndIf
section = 1;
sweep_length = length;
first_length = front;
last_length = 0;
sweep_layers = 0;
sweep_graded = 1;
Call Sweep;

// Named groups a scene can refer to (wall secondaries, clamps, parts).
Physical Surface("bottom") = {1};                     // z = z0
Physical Surface("top") = {sweep_top};                // z = z0 + length
Physical Surface("sides") = {sweep_lateral[]};
If (front > 0)
  Physical Volume("front") = {sweep_volumes[0]};
  Physical Volume("body") = {sweep_volumes[1]};
Else
  Physical Volume("body") = {sweep_volumes[0]};
EndIf
