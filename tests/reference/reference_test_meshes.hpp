#pragma once
// Meshes of the reference verification tests, built without gmsh: a box with its six faces
// named, the MacNeal–Harder 3-D patch, and Cook's membrane.

#include "meshes/tet_mesh.hpp"
#include "reference/finite_strain_solver.hpp"

#include <functional>
#include <string>

namespace kerf::reference::test {

/// box_tet_mesh with its surface groups replaced by the six faces `xmin`, `xmax`, `ymin`,
/// `ymax`, `zmin`, `zmax`, plus `boundary` (all boundary triangles).
TetMesh named_box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper, int nx, int ny, int nz);

/// Names the boundary of `mesh` by the bounding-box face each triangle lies on (as named_box).
void name_bounding_faces(TetMesh& mesh);

/// MacNeal & Harder (1985), "A proposed standard set of problems to test finite element
/// accuracy", Finite Elem. Anal. Des. 1, 3–20, Fig. 2: the unit cube cut into seven hexahedra by
/// eight interior nodes; each hexahedron split into 24 tetrahedra through its face and body
/// centres. Surface group `boundary`.
TetMesh macneal_harder_patch();

/// Cook's membrane as in the deal.II code gallery's "Quasi-Static Finite-Strain Compressible
/// Elasticity" (cook_membrane.cc, make_grid): the trapezoid (0,0), (48,44), (48,60), (0,44) mm,
/// 1 mm thick (z in [-0.5, 0.5] mm), n by n by 1 cells, each split into 6 tetrahedra. Surface
/// groups `xmin` (clamped), `xmax` (loaded), `zmin`, `zmax`. Units: metres.
TetMesh cook_membrane(int n);

/// Cook's membrane problem of the code gallery on `mesh` (cook_membrane(n), or a gmsh mesh with the
/// same surface groups): its decoupled neo-Hookean energy (μ = 422.5 kPa, ν = 0.3), `xmin`
/// clamped, the dead shear load (0, 1, 0) on `xmax`, and with `plane_strain` the faces `zmin` and
/// `zmax` sliding.
FiniteStrainProblem cook_membrane_problem(TetMesh mesh, bool plane_strain = true);

/// Adds the surface group `name`: the interior faces (shared by two tetrahedra) whose three nodes
/// all satisfy `on_surface`, e.g. a grid plane of a box mesh to be split into a crack path.
void add_interior_face_group(TetMesh& mesh, const std::string& name, const std::function<bool(const Eigen::Vector3d&)>& on_surface);

/// The affine patch problem: one material `body` (law, E, ν) on `mesh`, its surface group
/// `boundary` prescribed to u = load (G X + b). Any conforming element containing the linear
/// polynomials reproduces u = G X + b inside to round-off (Zienkiewicz & Taylor, vol. 1, §9.3).
FiniteStrainProblem affine_problem(TetMesh mesh, const Eigen::Matrix3d& G, const Eigen::Vector3d& b, LawKind law,
                                   double E, double nu);

} // namespace kerf::reference::test
