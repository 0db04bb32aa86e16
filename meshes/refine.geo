// Local refinement near a point, shared by the bodies' .geo files (Include "refine.geo").
//
// Every body here is a 2-D section in the plane z = z0 swept along its own z axis.
// The refinement acts in two parts:
//  - in the section: the distance to the point (refine_x, refine_y, z0) (the refinement
//    point seen in the section's plane) feeds a Threshold field, so that the element size
//    grows linearly from refine_size at the point to h at distance refine_radius;
//  - along the sweep (macro GradedLayers): layers graded by the same law in |z - refine_z|.
// The cells near the point are thus small in all three directions; cells in line with the
// point along z or across the section are small in two directions only.
//
// Expects h, z0, refine_size (0: no refinement), refine_radius, refine_x, refine_y, refine_z.

If (refine_size > 0)
  // The distance as an expression (not a Distance field to a Point: a point that falls on
  // one of the body's corner points would be merged into it by the built-in kernel).
  Field[1] = MathEval;
  Field[1].F = Sprintf("Sqrt((x - (%.17g))^2 + (y - (%.17g))^2 + (z - (%.17g))^2)",
                       refine_x, refine_y, z0);
  Field[2] = Threshold;
  Field[2].InField = 1;
  Field[2].SizeMin = refine_size;
  Field[2].SizeMax = h;
  Field[2].DistMin = 0;
  Field[2].DistMax = refine_radius;
  Background Field = 2;
  // The field alone sets the size (not the corner points' h, not curvature).
  Mesh.MeshSizeExtendFromBoundary = 0;
  Mesh.MeshSizeFromPoints = 0;
  Mesh.MeshSizeFromCurvature = 0;
EndIf

// Layers along a sweep of length layer_length starting at layer_start (the coordinate of
// the sections' plane): returns layer_counts[] and layer_heights[] (the cumulative fractions
// of the sweep, as Extrude's Layers{} wants them). Without refinement: uniform layers at most
// h thick. With refinement the size law s(d) = a + b d (d < refine_radius), h beyond, with
// a = refine_size and b = (h - a) / refine_radius, is integrated: n(d) = int_0^d dt / s(t)
// layers lie within d of refine_z; each side of refine_z gets Ceil(n(side)) layers placed
// at d(k n(side) / Ceil(n(side))), with the inverse d(n) in closed form.
Macro GradedLayers
  layer_counts[] = {};
  layer_heights[] = {};
  If (refine_size > 0)
    grade_b = (h - refine_size) / refine_radius;
    grade_nr = Log(h / refine_size) / grade_b;  // layers within refine_radius
    below = Min(Max(refine_z - layer_start, 0), layer_length);
    above = layer_length - below;
    grade_d = below;
    Call LayersWithin;
    n_below = Ceil(grade_n - 1e-9);
    If (n_below > 0)
      scale = grade_n / n_below;
      For k In {n_below - 1 : 0 : -1}
        grade_n = k * scale;
        Call DistanceOfLayers;
        layer_counts[] += 1;
        layer_heights[] += (below - grade_d) / layer_length;
      EndFor
    EndIf
    grade_d = above;
    Call LayersWithin;
    n_above = Ceil(grade_n - 1e-9);
    If (n_above > 0)
      scale = grade_n / n_above;
      For k In {1 : n_above}
        grade_n = k * scale;
        Call DistanceOfLayers;
        layer_counts[] += 1;
        layer_heights[] += (below + grade_d) / layer_length;
      EndFor
    EndIf
    layer_heights[#layer_heights[] - 1] = 1;  // exactly, whatever the round-off
  Else
    layer_counts[] = {Ceil(layer_length / h - 1e-9)};
    layer_heights[] = {1};
  EndIf
Return

Macro LayersWithin  // grade_n = n(grade_d)
  If (grade_d <= refine_radius)
    grade_n = Log(1 + grade_b * grade_d / refine_size) / grade_b;
  Else
    grade_n = grade_nr + (grade_d - refine_radius) / h;
  EndIf
Return

Macro DistanceOfLayers  // grade_d = d(grade_n), the inverse of LayersWithin
  If (grade_n <= grade_nr)
    grade_d = refine_size * (Exp(grade_b * grade_n) - 1) / grade_b;
  Else
    grade_d = refine_radius + (grade_n - grade_nr) * h;
  EndIf
Return
