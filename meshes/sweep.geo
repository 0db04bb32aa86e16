// The sweep of a body's section along its own z, in up to three regions, shared by the
// bodies' .geo files (Include "sweep.geo", after Include "refine.geo").
//
// Macro Sweep extrudes the surface `section` (in the plane z = z0) over sweep_length, in
// segments: the first first_length (0: none), the last last_length (0: none), and the
// middle one the rest. Each segment is a volume of its own, so that a scene can make it a
// part of another material ([[part]] naming the physical volume the .geo file gives it).
// With sweep_layers > 0 the layers through the sweep are about that many, shared among
// the segments in proportion to their lengths (at least one each, uniform in each);
// otherwise each segment gets uniform layers at most h thick, or with sweep_graded the
// layers of GradedLayers (refine.geo) over its own span, graded about refine_z when
// refined. One segment (no first, no last) is the sweep of old, layer for layer.
//
// Expects section, z0, sweep_length, first_length, last_length, sweep_layers,
// sweep_graded, hexahedra (and what refine.geo expects). Returns sweep_top (the far face), sweep_lateral[] (the
// lateral faces, segment after segment, each in the order of the section's boundary
// curves) and sweep_volumes[] (the segments' volumes, first to last).

Macro Sweep
  sweep_lateral[] = {};
  sweep_volumes[] = {};
  segment_lengths[] = {};
  If (first_length > 0)
    segment_lengths[] += first_length;
  EndIf
  segment_lengths[] += sweep_length - first_length - last_length;
  If (last_length > 0)
    segment_lengths[] += last_length;
  EndIf
  sweep_base = section;
  sweep_start = z0;
  For segment In {0 : #segment_lengths[] - 1}
    layer_start = sweep_start;
    layer_length = segment_lengths[segment];
    If (sweep_layers > 0)
      layer_counts[] = {Max(1, Round(sweep_layers * layer_length / sweep_length))};
      layer_heights[] = {1};
    ElseIf (sweep_graded)
      Call GradedLayers;
    Else
      layer_counts[] = {Ceil(layer_length / h - 1e-9)};
      layer_heights[] = {1};
    EndIf
    If (hexahedra)
      swept[] = Extrude {0, 0, layer_length} {
        Surface{sweep_base}; Layers{layer_counts[], layer_heights[]}; Recombine;
      };
    Else
      swept[] = Extrude {0, 0, layer_length} {
        Surface{sweep_base}; Layers{layer_counts[], layer_heights[]};
      };
    EndIf
    sweep_volumes[] += swept[1];
    sweep_lateral[] += swept[{2 : #swept[] - 1}];
    sweep_base = swept[0];
    sweep_start += layer_length;
  EndFor
  sweep_top = sweep_base;
Return

// The physical volumes of a plate's regions: "bottom_layer" (first_length > 0), "body",
// "top_layer" (last_length > 0).
Macro PlateRegions
  region = 0;
  If (first_length > 0)
    Physical Volume("bottom_layer") = {sweep_volumes[region]};
    region += 1;
  EndIf
  Physical Volume("body") = {sweep_volumes[region]};
  If (last_length > 0)
    Physical Volume("top_layer") = {sweep_volumes[region + 1]};
  EndIf
Return
