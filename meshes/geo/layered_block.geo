// Two-layer block with internal, conformingly meshed cut plane x = cut_offset and layer
// interface z = depth - upper_thickness. Units: metres. x along the long axis (x in [0, length]),
// y across the width (centred), z up (base at z = 0).
// Physical groups: volumes `body` (all), `layer_lower` (z < depth - upper_thickness),
// `layer_upper`; surfaces `support` (z = 0), `top` (z = depth), `cut_plane` (internal),
// `layer_interface` (internal), `sides`.
SetFactory("OpenCASCADE");

DefineConstant[
  length = {0.040, Min 1e-6, Name "Parameters/length"},
  width = {0.020, Min 1e-6, Name "Parameters/width"},
  depth = {0.020, Min 1e-6, Name "Parameters/depth"},
  upper_thickness = {0.006, Min 1e-6, Name "Parameters/upper_thickness"}
];
DefineConstant[
  cut_offset = {length / 2, Name "Parameters/cut_offset"}
];
If (cut_offset <= 0 || cut_offset >= length)
  Error("layered_block.geo: cut_offset = %g must lie in (0, length = %g)", cut_offset, length);
EndIf
If (upper_thickness <= 0 || upper_thickness >= depth)
  Error("layered_block.geo: upper_thickness = %g must lie in (0, depth = %g)", upper_thickness, depth);
EndIf

z_interface = depth - upper_thickness;
// Four blocks (two layers x two sides of the cut), fragmented so that they share faces.
Box(1) = {0, -width / 2, 0, cut_offset, width, z_interface};
Box(2) = {cut_offset, -width / 2, 0, length - cut_offset, width, z_interface};
Box(3) = {0, -width / 2, z_interface, cut_offset, width, upper_thickness};
Box(4) = {cut_offset, -width / 2, z_interface, length - cut_offset, width, upper_thickness};
parts() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2, 3, 4}; Delete; };

// Selection tolerance: OpenCASCADE enlarges entity bounding boxes by its tolerance (~1e-7 m),
// so eps must exceed that (1 um for a 1 mm body), and stay far below the distance between
// distinct faces.
eps = 1e-3 * Min(length, Min(width, depth));
lower() = Volume In BoundingBox{-eps, -width / 2 - eps, -eps, length + eps, width / 2 + eps, z_interface + eps};
upper() = Volume In BoundingBox{-eps, -width / 2 - eps, z_interface - eps, length + eps, width / 2 + eps, depth + eps};
support() = Surface In BoundingBox{-eps, -width / 2 - eps, -eps, length + eps, width / 2 + eps, eps};
top() = Surface In BoundingBox{-eps, -width / 2 - eps, depth - eps, length + eps, width / 2 + eps, depth + eps};
cut() = Surface In BoundingBox{cut_offset - eps, -width / 2 - eps, -eps, cut_offset + eps, width / 2 + eps, depth + eps};
interface() = Surface In BoundingBox{-eps, -width / 2 - eps, z_interface - eps, length + eps, width / 2 + eps, z_interface + eps};
sides() = CombinedBoundary{ Volume{parts()}; };
sides() = Abs(sides());
sides() -= support();
sides() -= top();

If (#support() == 0 || #top() == 0 || #cut() == 0 || #sides() == 0 || #interface() == 0 || #lower() == 0 || #upper() == 0)
  Error("layered_block.geo: a physical group selection came out empty (bounding-box tolerance eps = %g)", eps);
EndIf

Physical Volume("body") = {parts()};
Physical Volume("layer_lower") = {lower()};
Physical Volume("layer_upper") = {upper()};
Physical Surface("support") = {support()};
Physical Surface("top") = {top()};
Physical Surface("cut_plane") = {cut()};
Physical Surface("layer_interface") = {interface()};
Physical Surface("sides") = {sides()};
