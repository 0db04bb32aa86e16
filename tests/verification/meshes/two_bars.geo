// Two square bars of side a and length L along z, the second a distance s beyond the
// first, shifted by dx across: two pieces of one mesh, the regions "left" and "right".
// Structured hexahedra of size h; the end faces are the groups "left_end" (z = 0) and
// "right_end" (z = 2 L + s).
DefineConstant[
  a = {0.004, Name "a"},
  L = {0.02, Name "L"},
  s = {0.0002, Name "s"},
  dx = {0, Name "dx"},
  h = {0.001, Name "h"}
];
n = Round(a / h);
m = Round(L / h);
For k In {0 : 1}
  z = k * (L + s);
  x = k * dx;
  p = newp;
  Point(p) = {x, 0, z, h};
  Point(p + 1) = {x + a, 0, z, h};
  Point(p + 2) = {x + a, a, z, h};
  Point(p + 3) = {x, a, z, h};
  l = newl;
  Line(l) = {p, p + 1};
  Line(l + 1) = {p + 1, p + 2};
  Line(l + 2) = {p + 2, p + 3};
  Line(l + 3) = {p + 3, p};
  c = newll;
  Curve Loop(c) = {l, l + 1, l + 2, l + 3};
  base = news;
  Plane Surface(base) = {c};
  Transfinite Curve {l : l + 3} = n + 1;
  Transfinite Surface {base};
  Recombine Surface {base};
  out[] = Extrude {0, 0, L} { Surface{base}; Layers{m}; Recombine; };
  If (k == 0)
    Physical Volume("left") = {out[1]};
    Physical Surface("left_end") = {base};
  Else
    Physical Volume("right") = {out[1]};
    Physical Surface("right_end") = {out[0]};
  EndIf
EndFor
