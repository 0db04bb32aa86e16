// A circular target plate, for demos/perforation_weldox.toml: the plate of thickness
// `target_thickness` clamped along its rim at `clamp_radius`, struck at its centre, which
// is the origin (the plate lies between z = 0 and z = target_thickness). The whole plate is
// meshed: a quarter with symmetry conditions would let the projectile, a rigid wall on a
// free main node, be pushed sideways by the one quarter it meets.
//
// The section is meshed unstructured (quadrangles recombined by Blossom) with the size
// growing from `h_impact` within `fine_radius` of the centre to `h_rim` at the rim, then
// swept through the thickness in `target_layers` equal layers (0: the thickness / h_impact).
// Open it in the gmsh GUI to change the parameters; the demo and its test set them with
// -setnumber. Their names are not those of meshes/*.geo: gmsh 4.8 keeps a -setnumber value
// for the rest of the process, and would hand a built-in shape's `thickness` to this file.
DefineConstant[
  target_thickness = {0.012, Min 1e-6, Name "Parameters/thickness"},
  clamp_radius = {0.25, Min 1e-6, Name "Parameters/radius of the clamped rim"},
  h_impact = {2e-3, Min 1e-6, Name "Parameters/element size at the impact"},
  fine_radius = {0.016, Min 0, Name "Parameters/radius of the fine zone"},
  h_rim = {0.015, Min 1e-6, Name "Parameters/element size at the rim"},
  target_layers = {0, Min 0, Step 1, Name "Parameters/layers through the thickness (0: auto)"}
];

nz = target_layers;
If (nz < 1)
  nz = Round(target_thickness / h_impact);
EndIf

Point(1) = {0, 0, 0, h_impact};
Point(2) = {clamp_radius, 0, 0, h_rim};
Point(3) = {0, clamp_radius, 0, h_rim};
Point(4) = {-clamp_radius, 0, 0, h_rim};
Point(5) = {0, -clamp_radius, 0, h_rim};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Circle(3) = {4, 1, 5};
Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};

// The size: h_impact within fine_radius of the centre, growing linearly to h_rim at the rim.
Field[1] = MathEval;
Field[1].F = "Sqrt(x^2 + y^2)";
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = h_impact;
Field[2].SizeMax = h_rim;
Field[2].DistMin = fine_radius;
Field[2].DistMax = clamp_radius;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;
Mesh.MeshSizeFromCurvature = 0;
Mesh.Algorithm = 6;
Mesh.RecombinationAlgorithm = 1;
Recombine Surface{1};

ez[] = Extrude {0, 0, target_thickness} { Surface{1}; Layers{nz}; Recombine; };

Physical Surface("bottom") = {1};                       // z = 0, the exit face
Physical Surface("top") = {ez[0]};                      // z = target_thickness: struck
Physical Surface("rim") = {ez[2], ez[3], ez[4], ez[5]}; // the clamped rim
Physical Volume("target") = {ez[1]};
