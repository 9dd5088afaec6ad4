// Quarter of a thick block for the Hertz indentation test of the reference (issue 3): the rigid
// sphere touches the top face's corner at the origin of the symmetry planes x = 0 and y = 0.
// Units: metres. x in [0, half_width], y in [0, half_width], z in [0, height] (top z = height).
// The element size is graded from `contact_size` within `contact_radius` of the top corner
// (0, 0, height) up to `far_size` at `grading_distance` (gmsh Distance + Threshold fields), and
// never exceeds the element size passed by the caller (Mesh.MeshSizeMax).
// Physical groups: volume `body`; surfaces `support` (z = 0), `top` (z = height), `symmetry_x`
// (x = 0), `symmetry_y` (y = 0), `sides` (x = half_width and y = half_width).
SetFactory("OpenCASCADE");

DefineConstant[
  half_width = {0.050, Min 1e-6, Name "Parameters/half_width"},
  height = {0.050, Min 1e-6, Name "Parameters/height"},
  contact_size = {0.0002, Min 1e-9, Name "Parameters/contact_size"},
  contact_radius = {0.0015, Min 0, Name "Parameters/contact_radius"},
  grading_distance = {0.040, Min 1e-9, Name "Parameters/grading_distance"},
  far_size = {0.008, Min 1e-9, Name "Parameters/far_size"}
];
If (grading_distance <= contact_radius)
  Error("hertz_block.geo: grading_distance = %g must exceed contact_radius = %g", grading_distance, contact_radius);
EndIf

Box(1) = {0, 0, 0, half_width, half_width, height};
eps = 1e-3 * Min(half_width, height);
corner() = Point In BoundingBox{-eps, -eps, height - eps, eps, eps, height + eps};
If (#corner() != 1)
  Error("hertz_block.geo: the top corner (0, 0, height) was not found");
EndIf

Field[1] = Distance;
Field[1].PointsList = {corner()};
Field[2] = Threshold;
Field[2].InField = 1;
Field[2].SizeMin = contact_size;
Field[2].SizeMax = far_size; // and at most the caller's element size (Mesh.MeshSizeMax)
Field[2].DistMin = contact_radius;
Field[2].DistMax = grading_distance;
Background Field = 2;
Mesh.MeshSizeExtendFromBoundary = 0;
Mesh.MeshSizeFromPoints = 0;

support() = Surface In BoundingBox{-eps, -eps, -eps, half_width + eps, half_width + eps, eps};
top() = Surface In BoundingBox{-eps, -eps, height - eps, half_width + eps, half_width + eps, height + eps};
symx() = Surface In BoundingBox{-eps, -eps, -eps, eps, half_width + eps, height + eps};
symy() = Surface In BoundingBox{-eps, -eps, -eps, half_width + eps, eps, height + eps};
sides() = Surface In BoundingBox{half_width - eps, -eps, -eps, half_width + eps, half_width + eps, height + eps};
sides() += Surface In BoundingBox{-eps, half_width - eps, -eps, half_width + eps, half_width + eps, height + eps};
If (#support() != 1 || #top() != 1 || #symx() != 1 || #symy() != 1 || #sides() != 2)
  Error("hertz_block.geo: a physical group selection came out wrong (bounding-box tolerance eps = %g)", eps);
EndIf

Physical Volume("body") = {1};
Physical Surface("support") = {support()};
Physical Surface("top") = {top()};
Physical Surface("symmetry_x") = {symx()};
Physical Surface("symmetry_y") = {symy()};
Physical Surface("sides") = {sides()};
