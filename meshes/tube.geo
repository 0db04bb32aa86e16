// Thin-walled tube as a mid-surface, for shells: its axis along its own z from the origin
// (x0, y0, z0), the centre of its bottom end, over `length` (m). The cross-section is a
// square of side `width` (section = 0) or a circle of diameter `width` (section = 1),
// both of the mid-surface.
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets them
// from the scene's [mesh] table with `-setnumber`, turns the tube so that its own z axis
// lies along the scene's axis, and adds the trigger dents (mesh.trigger_amplitude,
// trigger_wavelength: rwall_fem.meshing.tube_mesh) to the nodes. The mesh is structured:
// the section's perimeter in segments of at most h (a whole number on each side of the
// square), swept along z in layers of at most h; quadrangles, or each one split into two
// triangles.
//
// Region (physical surface): "body". Ends (physical curves): "bottom" (z = z0) and "top"
// (z = z0 + length).
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0 (centre of the bottom end)"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  width = {0.05, Min 1e-9, Name "Parameters/2Size/width (side or diameter)"},
  length = {0.2, Min 1e-9, Name "Parameters/2Size/length"},
  section = {0, Choices{0="square", 1="circle"}, Name "Parameters/2Size/section"},
  h = {0.005, Min 1e-9, Name "Parameters/3Mesh/element size"},
  quadrangles = {1, Choices{0="triangles", 1="quadrangles"}, Name "Parameters/3Mesh/cells"}
];

nz = Ceil(length / h - 1e-9);
a = width / 2;
If (section == 0)
  // Four sides, each in a whole number of segments.
  ns = Ceil(width / h - 1e-9);
  Point(1) = {x0 - a, y0 - a, z0, h};
  Point(2) = {x0 + a, y0 - a, z0, h};
  Point(3) = {x0 + a, y0 + a, z0, h};
  Point(4) = {x0 - a, y0 + a, z0, h};
Else
  // Four quarter circles, each in a whole number of segments.
  ns = Ceil(Pi * width / 4 / h - 1e-9);
  Point(5) = {x0, y0, z0, h};
  Point(1) = {x0 + a, y0, z0, h};
  Point(2) = {x0, y0 + a, z0, h};
  Point(3) = {x0 - a, y0, z0, h};
  Point(4) = {x0, y0 - a, z0, h};
EndIf
For k In {1 : 4}
  If (section == 0)
    Line(k) = {k, k % 4 + 1};
  Else
    Circle(k) = {k, 5, k % 4 + 1};
  EndIf
  Transfinite Curve{k} = ns + 1;
EndFor
sides[] = {};
tops[] = {};
For k In {1 : 4}
  If (quadrangles)
    e[] = Extrude {0, 0, length} { Curve{k}; Layers{nz}; Recombine; };
  Else
    e[] = Extrude {0, 0, length} { Curve{k}; Layers{nz}; };
  EndIf
  tops[] += e[0];
  sides[] += e[1];
EndFor
Coherence;
Physical Surface("body") = {sides[]};
Physical Curve("bottom") = {1, 2, 3, 4};
Physical Curve("top") = {tops[]};
