// Triangular prism with one internal, conformingly meshed cut plane x = cut_offset. Units: metres.
// x along the long axis (x in [0, length]); cross-section in the yz-plane with corners
// (y, z) = (-base_width/2, 0), (base_width/2, 0), (0, depth): the apex line is on top.
// Physical groups: volume `body`; surfaces `support` (z = 0), `top` (the two slanted faces),
// `cut_plane` (internal, x = cut_offset), `sides` (the end faces x = 0 and x = length).
// Optional grading of the crack path, as in rect_prism.geo: with cut_element_size > 0 the elements
// within cut_element_size of the cut plane and above z = depth - cut_refine_depth have that size,
// growing to cut_far_size over cut_grading_distance (a gmsh Box field; Mesh.MeshSizeMax caps it).
SetFactory("OpenCASCADE");

DefineConstant[
  length = {0.050, Min 1e-6, Name "Parameters/length"},
  base_width = {0.018, Min 1e-6, Name "Parameters/base_width"},
  depth = {0.017, Min 1e-6, Name "Parameters/depth"}
];
DefineConstant[
  cut_offset = {length / 2, Name "Parameters/cut_offset"},
  cut_element_size = {0, Min 0, Name "Parameters/cut_element_size"},
  cut_far_size = {0.002, Min 1e-9, Name "Parameters/cut_far_size"},
  cut_grading_distance = {0.004, Min 0, Name "Parameters/cut_grading_distance"}
];
DefineConstant[
  cut_refine_depth = {depth, Min 0, Name "Parameters/cut_refine_depth"}
];
If (cut_offset <= 0 || cut_offset >= length)
  Error("tri_prism.geo: cut_offset = %g must lie in (0, length = %g)", cut_offset, length);
EndIf

// One triangular cross-section at x = 0 and one at x = cut_offset, each extruded along x.
For k In {0 : 1}
  x0 = (k == 0) ? 0 : cut_offset;
  p1 = newp; Point(p1) = {x0, -base_width / 2, 0};
  p2 = newp; Point(p2) = {x0, base_width / 2, 0};
  p3 = newp; Point(p3) = {x0, 0, depth};
  l1 = newl; Line(l1) = {p1, p2};
  l2 = newl; Line(l2) = {p2, p3};
  l3 = newl; Line(l3) = {p3, p1};
  cl = newll; Curve Loop(cl) = {l1, l2, l3};
  s = news; Plane Surface(s) = {cl};
  dx = (k == 0) ? cut_offset : length - cut_offset;
  e() = Extrude{dx, 0, 0}{ Surface{s}; };
  half[k] = e(1);
EndFor
// Fragmenting the two halves makes them share the cut face, so the mesh is conforming across it.
parts() = BooleanFragments{ Volume{half[0]}; Delete; }{ Volume{half[1]}; Delete; };

// Selection tolerance: OpenCASCADE enlarges entity bounding boxes by its tolerance (~1e-7 m),
// so eps must exceed that (1 um for a 1 mm body), and stay far below the distance between
// distinct faces.
eps = 1e-3 * Min(length, Min(base_width, depth));
support() = Surface In BoundingBox{-eps, -base_width / 2 - eps, -eps, length + eps, base_width / 2 + eps, eps};
cut() = Surface In BoundingBox{cut_offset - eps, -base_width / 2 - eps, -eps, cut_offset + eps, base_width / 2 + eps, depth + eps};
sides() = Surface In BoundingBox{-eps, -base_width / 2 - eps, -eps, eps, base_width / 2 + eps, depth + eps};
sides() += Surface In BoundingBox{length - eps, -base_width / 2 - eps, -eps, length + eps, base_width / 2 + eps, depth + eps};
top() = CombinedBoundary{ Volume{parts()}; };
top() = Abs(top());
top() -= support();
top() -= sides();

If (#support() == 0 || #top() == 0 || #cut() == 0 || #sides() == 0)
  Error("tri_prism.geo: a physical group selection came out empty (bounding-box tolerance eps = %g)", eps);
EndIf

If (cut_element_size > 0)
  Field[1] = Box;
  Field[1].VIn = cut_element_size;
  Field[1].VOut = cut_far_size;
  Field[1].Thickness = cut_grading_distance;
  Field[1].XMin = cut_offset - cut_element_size;
  Field[1].XMax = cut_offset + cut_element_size;
  Field[1].YMin = -base_width / 2 - eps;
  Field[1].YMax = base_width / 2 + eps;
  Field[1].ZMin = depth - cut_refine_depth;
  Field[1].ZMax = depth + eps;
  Background Field = 1;
  Mesh.MeshSizeExtendFromBoundary = 0;
  Mesh.MeshSizeFromPoints = 0;
EndIf

Physical Volume("body") = {parts()};
Physical Surface("support") = {support()};
Physical Surface("top") = {top()};
Physical Surface("cut_plane") = {cut()};
Physical Surface("sides") = {sides()};
