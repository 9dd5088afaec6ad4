// The cohesive interface of the finite-strain reference against linear-elastic fracture mechanics:
// a double cantilever beam (DCB) opened in mode I by prescribed displacements of its two arm ends.
// Expected values: Williams' corrected beam theory (Williams 1989, "End corrections for orthotropic
// DCB specimens", Compos. Sci. Technol. 35, 367–376; the "modified beam theory" of ASTM D5528),
// with the crack length a corrected to a + χh for the root rotation and shear of the arms:
//
//   compliance       δ = 2 P (a + χh)³ / (3 E I)               (both arms, opening at the load line)
//   energy release   G = P² (a + χh)² / (B E I)
//   initiation       G = J_c at a = a₀:  P_c = sqrt(J_c B E I) / (a₀ + χh),  δ_c = 2 P_c (a₀ + χh)³ / (3 E I)
//   propagation      G = J_c while the crack grows:  P(δ) = [2 (J_c B E I)^{3/2} / (3 E I δ)]^{1/2}
//   χ (ν = 0)        χ = sqrt(E/(11 G) (3 − 2 (Γ/(1 + Γ))²)),  Γ = 1.18 E/G  (Williams 1989, Eq. 24;
//                    E/G = 2 for ν = 0: χ = 0.6051)
//
// with I = B h³/12 the second moment of one arm (thickness h, width B). The cohesive model tends to
// this curve as its process zone becomes small against the arm (LEFM is its limit) and as the mesh
// resolves the zone. The mesh is graded along the ligament: fine elements where the crack tip travels,
// coarse ones in the arms' cracked part and behind the ligament.
//
// `ctest` runs the coarsest mesh that is within 5% of LEFM (about a minute of CPU); the
// convergence table of docs/cohesive-fracture.md is printed by the disabled test:
//   build/tests/reference/test_reference_double_cantilever_beam --gtest_also_run_disabled_tests
//       --gtest_filter='*ConvergenceTable*'   (one line)

#include "meshes/crack_split.hpp"
#include "reference/cohesive/cohesive_zone.hpp"
#include "reference/finite_strain_solver.hpp"
#include "reference/load_path.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include "tests/reference/proportional_load.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

namespace kerf::reference {
namespace {

using test::add_interior_face_group;
using test::named_box;

/// The specimen and its LEFM closed forms (file comment).
struct DoubleCantileverBeam {
  // Stiff and brittle enough that the arms rotate little (δ_c ≈ 0.23 mm over a 33 mm arm: beam
  // theory is linear), with σ_c and J_c such that the cohesive zone, l_cz = (9π/32) E J_c/σ_c² =
  // 3.5 mm (Rice 1980; reference/cohesive/cohesive_zone.hpp), spans 3.5 elements of the ctest mesh
  // (1 mm) and stays small against a₀ + χh = 33 mm. With σ_c = 10 MPa (l_cz = 0.9 mm) the crack
  // advances by element-scale snap-backs on 1 mm elements that displacement control cannot follow
  // without viscous regularisation (docs/cohesive-fracture.md). Assumed values (a verification
  // specimen, not a material).
  double length = 60e-3, width = 5e-3, arm = 5e-3, crack = 30e-3; // L, B, h, a₀ [m]
  double youngs = 10e9;                                            // E [Pa], ν = 0
  double toughness = 10.0, strength = 5e6;                         // J_c [J/m²], σ_c [Pa]

  [[nodiscard]] double EI() const { return youngs * width * arm * arm * arm / 12.0; }
  /// Williams 1989, Eq. 24, isotropic with ν = 0 (E/G = 2).
  [[nodiscard]] static double chi() {
    const double e_over_g = 2.0, gamma = 1.18 * e_over_g, r = gamma / (1.0 + gamma);
    return std::sqrt(e_over_g / 11.0 * (3.0 - 2.0 * r * r));
  }
  [[nodiscard]] double initiation_load() const { return std::sqrt(toughness * width * EI()) / (crack + chi() * arm); }
  [[nodiscard]] double initiation_opening() const {
    const double a = crack + chi() * arm;
    return 2.0 * initiation_load() * a * a * a / (3.0 * EI());
  }
  [[nodiscard]] double propagation_load(double opening) const {
    return std::sqrt(2.0 * std::pow(toughness * width * EI(), 1.5) / (3.0 * EI() * opening));
  }
};

/// Grid coordinates on [0, length]: spacing `fine` on [fine_begin, fine_end], growing by the factor
/// `growth` per element away from it up to `coarse`, each side's last element stretched to end exactly
/// at the boundary.
std::vector<double> graded_coordinates(double length, double fine_begin, double fine_end, double fine, double coarse,
                                       double growth = 1.5) {
  // The steps of one side, from the fine part outwards, scaled to fill `extent` exactly.
  auto side = [&](double extent) {
    std::vector<double> steps;
    double h = fine, covered = 0.0;
    while (covered < extent - 1e-12) {
      h = std::min(coarse, h * growth);
      steps.push_back(h);
      covered += h;
    }
    for (double& s : steps) s *= extent / covered;
    return steps;
  };
  std::vector<double> x{0.0};
  const std::vector<double> left = side(fine_begin);
  for (auto it = left.rbegin(); it + 1 < left.rend(); ++it) x.push_back(x.back() + *it); // up to fine_begin (excluded)
  if (left.empty()) x.clear();
  const int n_fine = static_cast<int>(std::lround((fine_end - fine_begin) / fine));
  for (int i = 0; i <= n_fine; ++i) x.push_back(fine_begin + (fine_end - fine_begin) * i / n_fine);
  for (double s : side(length - fine_end)) x.push_back(x.back() + s);
  x.back() = length;
  return x;
}

/// One mesh level of the study.
struct DcbMesh {
  double fine = 1e-3;     ///< element size along the ligament where the crack travels [m]
  int cells_per_arm = 2;  ///< elements through one arm's thickness (uniform)
};

/// One DCB run: the load–opening path and the energy ledger.
struct DcbResult {
  std::vector<std::pair<double, double>> curve; ///< (opening δ [m], load P [N])
  std::size_t dofs = 0, cells = 0;
  int newton = 0, cutbacks = 0;
  double seconds = 0.0;
  double work = 0.0, strain = 0.0, interface = 0.0, cohesive = 0.0;
  double peak = 0.0; ///< largest load [N]
  double failed_area = 0.0, damaged_area = 0.0; ///< at the end [m²]
};

DcbResult run_dcb(const DoubleCantileverBeam& d, const DcbMesh& m, double max_opening, int steps) {
  // Graded grid: fine from two elements behind the initial tip to 4 mm (the zone) beyond the LEFM tip
  // at the last opening: the crack grows by (a₀ + χh)(sqrt(max δ/δ_c) − 1), 8.7 mm at δ = 1.6 δ_c.
  const double growth = (d.crack + DoubleCantileverBeam::chi() * d.arm) * (std::sqrt(max_opening / d.initiation_opening()) - 1.0);
  // The initial tip a₀ is a grid line (two fine elements behind it): the pre-crack and the ligament meet there.
  const double ahead = std::ceil((growth + 4e-3) / m.fine) * m.fine;
  const std::vector<double> xs = graded_coordinates(d.length, d.crack - 2.0 * m.fine, d.crack + ahead, m.fine, 2.5e-3);
  const int nx = static_cast<int>(xs.size()) - 1, nz = 2 * m.cells_per_arm;
  TetMesh mesh = named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(nx, 1, nz), nx, 1, nz);
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v) {
    mesh.nodes(v, 0) = xs[static_cast<std::size_t>(std::lround(mesh.nodes(v, 0)))];
    mesh.nodes(v, 1) *= d.width;
    mesh.nodes(v, 2) *= 2.0 * d.arm / nz;
  }
  const double tol = 1e-9 * d.length;
  add_interior_face_group(mesh, "precrack", [&](const Eigen::Vector3d& x) { return std::abs(x.z() - d.arm) < tol && x.x() <= d.crack + tol; });
  add_interior_face_group(mesh, "ligament", [&](const Eigen::Vector3d& x) { return std::abs(x.z() - d.arm) < tol && x.x() >= d.crack - tol; });
  // The two arms' end faces (x = 0), each loaded on its own.
  for (const bool upper : {true, false}) {
    const SurfaceGroup* xmin = mesh.find_surface_group("xmin");
    std::vector<int> rows;
    for (Eigen::Index f = 0; f < xmin->triangles.rows(); ++f) {
      double zc = 0.0;
      for (int j = 0; j < 3; ++j) zc += mesh.nodes(xmin->triangles(f, j), 2) / 3.0;
      if ((zc > d.arm) == upper) rows.push_back(static_cast<int>(f));
    }
    SurfaceGroup g{upper ? "load_upper" : "load_lower", upper ? 201 : 202, Eigen::MatrixXi(static_cast<Eigen::Index>(rows.size()), 3)};
    for (std::size_t r = 0; r < rows.size(); ++r) g.triangles.row(static_cast<Eigen::Index>(r)) = xmin->triangles.row(rows[r]);
    mesh.surface_groups.push_back(std::move(g));
  }
  // The pre-crack is free (no cohesive law); the ligament is the cohesive interface.
  const TetMesh split = split_along_surface(split_along_surface(mesh, "precrack").mesh, "ligament").mesh;

  FiniteStrainProblem problem;
  problem.mesh = split;
  problem.materials = {{"body", LawKind::neo_hookean, d.youngs, 0.0}};
  problem.displacement_boundaries.push_back({"xmax", DisplacementBoundary::Kind::bonded, {}, {true, true, true}});
  // u_z = ±δ/2 on the arm ends (x and y free: the end faces rotate freely about y, a load line).
  problem.displacement_boundaries.push_back({"load_upper", DisplacementBoundary::Kind::prescribed,
                                             [&](const Eigen::Vector3d&, double f) { return Eigen::Vector3d(0, 0, 0.5 * f * max_opening); },
                                             {false, false, true}});
  problem.displacement_boundaries.push_back({"load_lower", DisplacementBoundary::Kind::prescribed,
                                             [&](const Eigen::Vector3d&, double f) { return Eigen::Vector3d(0, 0, -0.5 * f * max_opening); },
                                             {false, false, true}});
  CohesiveInterfaceSpec spec{"ligament+", "ligament-", {}};
  spec.law.cohesive_strength = d.strength;
  spec.law.fracture_toughness = d.toughness;
  problem.cohesive = spec;
  SolverSettings settings;
  settings.degree = 2;
  const auto t0 = std::chrono::steady_clock::now();
  FiniteStrainSolver solver(problem, settings);
  LoadPath path(solver, LoadState{}, LoadPathSettings{10});
  DcbResult r;
  r.dofs = solver.dof_count();
  r.cells = solver.cell_count();
  double previous_upper = 0.0, previous_lower = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const LoadTarget target = test::proportional_target(k, steps);
    const LoadStepReport step = path.advance(target);
    r.newton += step.newton_iterations;
    r.cutbacks += step.cutbacks;
    // The loader's force on each arm: minus the reaction (the body on the support).
    const double upper = -step.equilibrium.boundary_reactions[1].force.z();
    const double lower = -step.equilibrium.boundary_reactions[2].force.z();
    // External work, trapezoid rule per arm: W = Σ ½ (F_k + F_{k−1}) Δu, u = ±δ/2.
    r.work += 0.5 * (upper + previous_upper) * 0.5 * max_opening / steps - 0.5 * (lower + previous_lower) * 0.5 * max_opening / steps;
    previous_upper = upper;
    previous_lower = lower;
    const double opening = target.load.load_factor * max_opening;
    r.curve.emplace_back(opening, upper);
    const CohesiveSummary& c = step.equilibrium.cohesive;
    if (upper > r.peak) {
      r.peak = upper;
    }
    r.interface = c.stored_energy;
    r.cohesive = c.dissipated_energy;
    r.failed_area = c.failed_area;
    r.damaged_area = c.damaged_area;
  }
  r.strain = solver.strain_energy();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

/// Errors of one run against LEFM.
struct DcbErrors {
  double peak = 0.0;      ///< P_max / P_c − 1
  double curve = 0.0;     ///< max |P / P_LEFM(δ) − 1| over δ in [1.25 δ_c, max δ]
  double balance = 0.0;   ///< (U + U_int + D) / W − 1
};

DcbErrors errors(const DoubleCantileverBeam& d, const DcbResult& r) {
  DcbErrors e;
  const double dc = d.initiation_opening();
  e.peak = r.peak / d.initiation_load() - 1.0;
  // After initiation: the cohesive zone rounds LEFM's corner at δ_c, so the curve is compared from
  // 1.25 δ_c on, where the crack has grown by ≈ 0.12 (a₀ + χh) ≈ 4 mm. The LEFM curve after
  // initiation does not depend on a₀ or χ, only on G = J_c and the beams' E I.
  for (const auto& [delta, load] : r.curve)
    if (delta >= 1.25 * dc) e.curve = std::max(e.curve, std::abs(load / d.propagation_load(delta) - 1.0));
  e.balance = (r.strain + r.interface + r.cohesive) / r.work - 1.0;
  return e;
}

void print_row(const DcbMesh& m, const DcbResult& r, const DcbErrors& e) {
  const double zone = (r.damaged_area - r.failed_area) / DoubleCantileverBeam{}.width;
  std::printf("| %.3g | %d | %zu | %zu | %.2f (%.1f) | %+.2f%% | %.2f%% | %+.3f%% | %d | %d | %.0f |\n", m.fine * 1e3,
              m.cells_per_arm, r.cells, r.dofs, zone * 1e3, zone / m.fine, 100 * e.peak, 100 * e.curve, 100 * e.balance,
              r.newton, r.cutbacks, r.seconds);
  std::fflush(stdout);
}

void print_header(const DoubleCantileverBeam& d) {
  const double rice = cohesive_zone_length(d.youngs, 0.0, d.toughness, d.strength);
  std::printf("DCB: LEFM (Williams' corrected beam theory, χ = %.4f) P_c = %.4f N at δ_c = %.4f mm; Rice's l_cz = %.3f mm\n",
              DoubleCantileverBeam::chi(), d.initiation_load(), d.initiation_opening() * 1e3, rice * 1e3);
  std::printf("| fine h [mm] | cells per arm | cells | DOFs | softening zone at the end [mm] (elements) | P_max/P_c − 1 "
              "| max |P/P_LEFM − 1|, δ ≥ 1.25 δ_c | energy balance | Newton its | cut-backs | wall [s] |\n");
  std::fflush(stdout);
}

constexpr int kSteps = 48;               // load steps to δ = 1.6 δ_c (no viscosity: cut-backs carry the path)
constexpr double kMaxOpeningRatio = 1.6; // δ_max / δ_c: the crack grows by ≈ 8.7 mm

TEST(DoubleCantileverBeam, GradedMeshFollowsLinearElasticFractureMechanics) {
  const DoubleCantileverBeam d;
  print_header(d);
  const DcbMesh mesh{1e-3, 2};
  const DcbResult r = run_dcb(d, mesh, kMaxOpeningRatio * d.initiation_opening(), kSteps);
  const DcbErrors e = errors(d, r);
  print_row(mesh, r, e);
  // Required: critical load and the post-initiation curve within 5% of LEFM (Williams' corrected
  // beam theory above).
  EXPECT_LT(std::abs(e.peak), 0.05);
  EXPECT_LT(e.curve, 0.05);
  // External work = strain energy + interface energy + dissipation (trapezoid rule: 1%).
  EXPECT_NEAR(e.balance, 0.0, 0.01);
  // The crack grew (LEFM: by ≈ 8.7 mm), and the dissipation is J_c per failed area plus the partly
  // dissipated zone ahead: J_c A_failed <= D <= J_c A_damaged.
  EXPECT_GT(r.failed_area, 5e-3 * d.width);
  EXPECT_GE(r.cohesive, d.toughness * r.failed_area);
  EXPECT_LE(r.cohesive, d.toughness * r.damaged_area);
}

TEST(DoubleCantileverBeam, DISABLED_ConvergenceTable) {
  const DoubleCantileverBeam d;
  print_header(d);
  for (const DcbMesh m : {DcbMesh{2e-3, 2}, DcbMesh{1e-3, 2}, DcbMesh{0.5e-3, 2}, DcbMesh{0.5e-3, 4}}) {
    try {
      const DcbResult r = run_dcb(d, m, kMaxOpeningRatio * d.initiation_opening(), kSteps);
      print_row(m, r, errors(d, r));
    } catch (const LoadPathError& e) {
      // An under-resolved zone: the crack jumps by an element and displacement control cannot follow.
      std::printf("| %.3g | %d | the path stops at sample %zu of %d (δ = %.2f δ_c): cut-backs exhausted |\n", m.fine * 1e3,
                  m.cells_per_arm, e.sample(), kSteps, kMaxOpeningRatio * static_cast<double>(e.sample()) / kSteps);
      std::fflush(stdout);
    }
  }
}

} // namespace
} // namespace kerf::reference
