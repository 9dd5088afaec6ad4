// Cook's membrane (Cook 1974; the deal.II code gallery's "Quasi-Static Finite-Strain Compressible
// Elasticity"): the trapezoid (0,0)-(48,44)-(48,60)-(0,44) mm extruded through its thickness
// (z from -thickness/2 to +thickness/2) in one layer of tetrahedra. Units: metres.
// The right edge has a point at y = 52 mm, so that the tip (48, 52, ±thickness/2) mm is a node.
// Physical groups: volume `body`; surfaces `xmin` (clamped, x = 0), `xmax` (the loaded edge,
// x = 48 mm), `zmin` and `zmax` (the two faces, u_z = 0 for plane strain).
DefineConstant[
  thickness = {0.001, Min 1e-6, Name "Parameters/thickness"}
];
mm = 1e-3;
Point(1) = {0, 0, -thickness / 2};
Point(2) = {48 * mm, 44 * mm, -thickness / 2};
Point(3) = {48 * mm, 52 * mm, -thickness / 2};
Point(4) = {48 * mm, 60 * mm, -thickness / 2};
Point(5) = {0, 44 * mm, -thickness / 2};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 5};
Line(5) = {5, 1};
Curve Loop(1) = {1, 2, 3, 4, 5};
Plane Surface(1) = {1};
// out[0]: the top face, out[1]: the volume, out[2 + k]: the side swept by line k + 1.
out[] = Extrude {0, 0, thickness} { Surface{1}; Layers{1}; };
Physical Volume("body") = {out[1]};
Physical Surface("xmin") = {out[6]};
Physical Surface("xmax") = {out[3], out[4]};
Physical Surface("zmin") = {1};
Physical Surface("zmax") = {out[0]};
