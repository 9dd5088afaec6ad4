// Rectangular prism with one internal, conformingly meshed cut plane. Units: metres.
// x along the long axis (x in [0, length]), y across the width (centred), z up (base at z = 0).
// Physical groups: volume `body`; surfaces `support` (z = 0), `top` (z = depth), `cut_plane`
// (internal: x = cut_offset if cut_normal = 0, y = cut_offset if cut_normal = 1), `sides`.
// Optional grading for a cohesive crack path (docs/cohesive-fracture.md): with cut_element_size > 0
// the elements within cut_element_size of the cut plane and above z = depth - cut_refine_depth have
// that size, growing linearly to cut_far_size over cut_grading_distance (a gmsh Box field with a
// transition layer; the caller's element size, Mesh.MeshSizeMax, caps it); 0 (the default) meshes
// uniformly.
// Optional grasp discs (a stylus that grasps the top face, paper 000 §2.1-2.2): with
// grasp1_radius > 0 the top face holds a conformingly meshed disc of that radius centred at
// (grasp1_x, grasp1_y), the physical surface `grasp1` (also part of `top`); grasp2_* likewise.
// grasp_element_size > 0 grades the mesh to that size on each rim, growing linearly with the
// distance d from it, s = grasp_element_size + grasp_size_growth d, up to the caller's element size
// (a gmsh Distance field on the rims and a MathEval of it).
// kerf sets these from the scene (experiments/run/scene_mesh.cpp); a .geo user may set them by hand.
SetFactory("OpenCASCADE");

DefineConstant[
  length = {0.040, Min 1e-6, Name "Parameters/length"},
  width = {0.020, Min 1e-6, Name "Parameters/width"},
  depth = {0.015, Min 1e-6, Name "Parameters/depth"},
  cut_normal = {0, Choices{0, 1}, Name "Parameters/cut_normal"},
  cut_element_size = {0, Min 0, Name "Parameters/cut_element_size"},
  cut_far_size = {0.002, Min 1e-9, Name "Parameters/cut_far_size"},
  cut_grading_distance = {0.004, Min 0, Name "Parameters/cut_grading_distance"},
  grasp1_radius = {0, Min 0, Name "Parameters/grasp1_radius"},
  grasp1_x = {0, Name "Parameters/grasp1_x"},
  grasp1_y = {0, Name "Parameters/grasp1_y"},
  grasp2_radius = {0, Min 0, Name "Parameters/grasp2_radius"},
  grasp2_x = {0, Name "Parameters/grasp2_x"},
  grasp2_y = {0, Name "Parameters/grasp2_y"},
  grasp_element_size = {0, Min 0, Name "Parameters/grasp_element_size"},
  grasp_size_growth = {0.5, Min 0, Name "Parameters/grasp_size_growth"}
];
// The cut plane sits mid-length (cut_normal 0) or on the centre line (cut_normal 1) by default.
DefineConstant[
  cut_offset = {(cut_normal == 0) ? length / 2 : 0, Name "Parameters/cut_offset"},
  cut_refine_depth = {depth, Min 0, Name "Parameters/cut_refine_depth"}
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
// Grasp discs on the top face are fragmented in with them: the top face's mesh conforms to each rim.
discs() = {};
grasp_r[] = {grasp1_radius, grasp2_radius};
grasp_x[] = {grasp1_x, grasp2_x};
grasp_y[] = {grasp1_y, grasp2_y};
For g In {0 : 1}
  If (grasp_r[g] > 0)
    If (grasp_x[g] - grasp_r[g] <= 0 || grasp_x[g] + grasp_r[g] >= length ||
        grasp_y[g] - grasp_r[g] <= -width / 2 || grasp_y[g] + grasp_r[g] >= width / 2)
      Error("rect_prism.geo: grasp%g disc (centre %g, %g, radius %g) must lie inside the top face", g + 1, grasp_x[g], grasp_y[g], grasp_r[g]);
    EndIf
    d = news; Disk(d) = {grasp_x[g], grasp_y[g], depth, grasp_r[g]};
    discs() += {d};
  EndIf
EndFor
If (#discs() == 0)
  parts() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; };
Else
  parts() = BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Surface{discs()}; Delete; };
EndIf
parts() = Volume{:};

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

// Each grasp disc's faces (the cut plane may split a disc in two halves).
grasp1() = {};
grasp2() = {};
For g In {0 : 1}
  If (grasp_r[g] > 0)
    faces() = Surface In BoundingBox{grasp_x[g] - grasp_r[g] - eps, grasp_y[g] - grasp_r[g] - eps, depth - eps,
                                     grasp_x[g] + grasp_r[g] + eps, grasp_y[g] + grasp_r[g] + eps, depth + eps};
    If (#faces() == 0)
      Error("rect_prism.geo: the grasp%g disc's faces were not found (bounding-box tolerance eps = %g)", g + 1, eps);
    EndIf
    If (g == 0)
      grasp1() = faces();
    Else
      grasp2() = faces();
    EndIf
  EndIf
EndFor

size_fields() = {};
If (cut_element_size > 0)
  Field[1] = Box;
  Field[1].VIn = cut_element_size;
  Field[1].VOut = cut_far_size;
  Field[1].Thickness = cut_grading_distance;
  If (cut_normal == 0)
    Field[1].XMin = cut_offset - cut_element_size;
    Field[1].XMax = cut_offset + cut_element_size;
    Field[1].YMin = -width / 2 - eps;
    Field[1].YMax = width / 2 + eps;
  Else
    Field[1].XMin = -eps;
    Field[1].XMax = length + eps;
    Field[1].YMin = cut_offset - cut_element_size;
    Field[1].YMax = cut_offset + cut_element_size;
  EndIf
  Field[1].ZMin = depth - cut_refine_depth;
  Field[1].ZMax = depth + eps;
  size_fields() += {1};
EndIf
If (grasp_element_size > 0 && #grasp1() + #grasp2() > 0)
  rims() = Abs(Boundary{ Surface{grasp1(), grasp2()}; });
  Field[2] = Distance;
  Field[2].CurvesList = {rims()};
  Field[2].NumPointsPerCurve = 200;
  // Size s0 on the rim, growing linearly with the distance d from it, s = s0 + g d (g =
  // grasp_size_growth), capped by the caller's element size (Mesh.MeshSizeMax).
  Field[4] = MathEval;
  Field[4].F = Sprintf("%.17g + %.17g * F2", grasp_element_size, grasp_size_growth);
  size_fields() += {4};
EndIf
If (#size_fields() == 1)
  Background Field = size_fields(0);
ElseIf (#size_fields() > 1)
  Field[10] = Min;
  Field[10].FieldsList = {size_fields()};
  Background Field = 10;
EndIf
If (#size_fields() > 0)
  Mesh.MeshSizeExtendFromBoundary = 0;
  Mesh.MeshSizeFromPoints = 0;
EndIf

If (#support() == 0 || #top() == 0 || #cut() == 0 || #sides() == 0)
  Error("rect_prism.geo: a physical group selection came out empty (bounding-box tolerance eps = %g)", eps);
EndIf

Physical Volume("body") = {parts()};
Physical Surface("support") = {support()};
Physical Surface("top") = {top()};
Physical Surface("cut_plane") = {cut()};
Physical Surface("sides") = {sides()};
If (#grasp1() > 0)
  Physical Surface("grasp1") = {grasp1()};
EndIf
If (#grasp2() > 0)
  Physical Surface("grasp2") = {grasp2()};
EndIf
