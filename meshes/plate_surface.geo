// Plate as a mid-surface, for shell elements: the rectangle from (x0, y0) to (x0 + lx,
// y0 + ly), in metres, at half the thickness above z0, z = z0 + thickness / 2 (the
// mid-plane of the box of plate.geo, so that a solid and a shell model of one plate share
// their scene keys).
//
// Open it in the gmsh GUI to change the parameters interactively; rwall_fem sets them
// from the scene's [mesh] table with `-setnumber` (and turns the plate so that its own z
// axis lies along the scene's axis afterwards). The mesh is structured: squares of side
// at most h (quadrangles), or each square split into two triangles. The thickness is the
// shells' (element.thickness, by default the plate's own).
//
// Region (physical surface): "body". Edges (physical curves, node sets for walls and
// boundary conditions): "side_x0", "side_x1" (x = x0, x0 + lx), "side_y0", "side_y1"
// (y = y0, y0 + ly); a facet carries one tag in DOLFINx, so the groups do not overlap.
DefineConstant[
  x0 = {0, Name "Parameters/1Origin/x0 (lowest corner)"},
  y0 = {0, Name "Parameters/1Origin/y0"},
  z0 = {0, Name "Parameters/1Origin/z0"},
  lx = {0.1, Min 1e-9, Name "Parameters/2Size/lx"},
  ly = {0.1, Min 1e-9, Name "Parameters/2Size/ly"},
  thickness = {0.002, Min 0, Name "Parameters/2Size/thickness"},
  h = {0.005, Min 1e-9, Name "Parameters/3Mesh/element size"},
  quadrangles = {1, Choices{0="triangles", 1="quadrangles"}, Name "Parameters/3Mesh/cells"}
];

nx = Ceil(lx / h - 1e-9);
ny = Ceil(ly / h - 1e-9);
Point(1) = {x0, y0, z0 + thickness / 2, h};
If (quadrangles)
  ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; Recombine; };
  ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; Recombine; };
Else
  ex[] = Extrude {lx, 0, 0} { Point{1}; Layers{nx}; };
  ey[] = Extrude {0, ly, 0} { Line{ex[1]}; Layers{ny}; };
EndIf
// ey[0]: the far edge (y = y0 + ly), ey[1]: the surface, ey[2], ey[3]: the edges at
// x = x0 + lx and x = x0 (swept from the line's end points); ex[1]: the edge at y = y0.
Physical Surface("body") = {ey[1]};
Physical Curve("side_y0") = {ex[1]};
Physical Curve("side_y1") = {ey[0]};
Physical Curve("side_x0") = {ey[3]};
Physical Curve("side_x1") = {ey[2]};
