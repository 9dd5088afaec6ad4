// Rectangular prism with one internal, conformingly meshed cut plane. Units: metres.
// x along the long axis (x in [0, length]), y across the width (centred), z up (base at z = 0).
// Physical groups: volume `body`; surfaces `support` (z = 0), `top` (z = depth), `cut_plane`
// (internal: x = cut_offset if cut_normal = 0, y = cut_offset if cut_normal = 1), `sides`.
SetFactory("OpenCASCADE");

DefineConstant[
  length = {0.040, Min 1e-6, Name "Parameters/length"},
  width = {0.020, Min 1e-6, Name "Parameters/width"},
  depth = {0.015, Min 1e-6, Name "Parameters/depth"},
  cut_normal = {0, Choices{0, 1}, Name "Parameters/cut_normal"}
];
// The cut plane sits mid-length (cut_normal 0) or on the centre line (cut_normal 1) by default.
DefineConstant[
  cut_offset = {(cut_normal == 0) ? length / 2 : 0, Name "Parameters/cut_offset"}
];

If (cut_normal != 0 && cut_normal != 1)
  Error("rect_prism.geo: cut_normal = %g must be 0 (plane x = cut_offset) or 1 (plane y = cut_offset)", cut_normal);
EndIf
If (cut_normal == 0)
  If (cut_offset <= 0 || cut_offset >= length)
    Error("rect_prism.geo: cut_offset = %g must lie in (0, length = %g)", cut_offset, length);
  EndIf
  Box(1) = {0, -width / 2, 0, cut_offset, width, depth};
  Box(2) = {cut_offset, -width / 2, 0, length - cut_offset, width, depth};
Else
  If (cut_offset <= -width / 2 || cut_offset >= width / 2)
    Error("rect_prism.geo: cut_offset = %g must lie in (-width/2, width/2), width = %g", cut_offset, width);
  EndIf
  Box(1) = {0, -width / 2, 0, length, cut_offset + width / 2, depth};
  Box(2) = {0, cut_offset, 0, length, width / 2 - cut_offset, depth};
EndIf
// Fragmenting the two halves makes them share the cut face, so the mesh is conforming across it.
parts() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };

// Selection tolerance: OpenCASCADE enlarges entity bounding boxes by its tolerance (~1e-7 m),
// so eps must exceed that (1 um for a 1 mm body), and stay far below the distance between
// distinct faces.
eps = 1e-3 * Min(length, Min(width, depth));
support() = Surface In BoundingBox{-eps, -width / 2 - eps, -eps, length + eps, width / 2 + eps, eps};
top() = Surface In BoundingBox{-eps, -width / 2 - eps, depth - eps, length + eps, width / 2 + eps, depth + eps};
If (cut_normal == 0)
  cut() = Surface In BoundingBox{cut_offset - eps, -width / 2 - eps, -eps, cut_offset + eps, width / 2 + eps, depth + eps};
Else
  cut() = Surface In BoundingBox{-eps, cut_offset - eps, -eps, length + eps, cut_offset + eps, depth + eps};
EndIf
sides() = CombinedBoundary{ Volume{parts()}; };
sides() = Abs(sides());
sides() -= support();
sides() -= top();

If (#support() == 0 || #top() == 0 || #cut() == 0 || #sides() == 0)
  Error("rect_prism.geo: a physical group selection came out empty (bounding-box tolerance eps = %g)", eps);
EndIf

Physical Volume("body") = {parts()};
Physical Surface("support") = {support()};
Physical Surface("top") = {top()};
Physical Surface("cut_plane") = {cut()};
Physical Surface("sides") = {sides()};
