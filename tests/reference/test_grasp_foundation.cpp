// The elastic foundation (FiniteStrainProblem::foundations, reference/solver/grasp_foundation.cpp),
// the compliant grasp of a stylus: traction k (d − u) on a surface towards an anchor displaced by d.
//
// 1. A column under uniaxial strain (lateral faces sliding, base sliding) whose top is held by a
//    foundation pulled up by δ: the layer (compliance 1/(kA)) and the column (H/(E_oed A), E_oed =
//    E(1−ν)/((1+ν)(1−2ν)) the oedometric modulus) are two springs in series, so in small strain
//    F = δ / (1/(kA) + H/(E_oed A)), the top moves by u = F H/(E_oed A) and the layer stores
//    ½ F²/(kA). δ is 10⁻⁶ H: the finite-strain terms are ~10⁻⁶ of the answer.
// 2. A stiff layer recovers the rigid tie: a central patch of the top pulled up 0.5 mm on a
//    bonded block, by a prescribed displacement (tie) and by foundations of growing k. A penalty
//    (the foundation is one) converges to its constraint at order 1/k: the difference to the tie
//    falls tenfold for a tenfold k, and is below 10⁻³ of the force at k = 10⁴ E/h.

#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace kerf::reference {
namespace {

TEST(GraspFoundation, ColumnUnderUniaxialStrainIsTwoSpringsInSeries) {
  const double E = 1e6, nu = 0.3, L = 0.01, H = 0.02, k = 1e8;
  const double E_oed = E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const double A = L * L, delta = 1e-6 * H;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, L, H), 2, 2, 3);
  p.materials.push_back({"body", LawKind::neo_hookean, E, nu});
  for (const char* s : {"xmin", "xmax", "ymin", "ymax", "zmin"})
    p.displacement_boundaries.push_back({s, DisplacementBoundary::Kind::sliding, {}, {}});
  p.foundations.push_back({"zmax", k, [&](const Eigen::Vector3d&, double load) -> Eigen::Vector3d {
                             return {0.0, 0.0, load * delta};
                           }, {}}); // {}: a uniform layer
  for (const int degree : {1, 2}) {
    SCOPED_TRACE(degree);
    SolverSettings settings;
    settings.degree = degree;
    FiniteStrainSolver solver(p, settings);
    const EquilibriumReport r = solver.solve({1.0, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(r.converged) << r.failure;
    const double F = delta / (1.0 / (k * A) + H / (E_oed * A));
    ASSERT_EQ(r.foundation_forces.size(), 1u);
    // Body on anchor: the column holds the anchor back, −F along z.
    EXPECT_NEAR(r.foundation_forces[0].z(), -F, 1e-4 * F);
    EXPECT_LT(r.foundation_forces[0].head<2>().norm(), 1e-6 * F);
    EXPECT_NEAR(solver.displacement_at(Eigen::Vector3d(0.5 * L, 0.5 * L, H)).z(), F * H / (E_oed * A), 1e-4 * F * H / (E_oed * A));
    EXPECT_NEAR(r.foundation_energy, 0.5 * F * F / (k * A), 1e-3 * 0.5 * F * F / (k * A));
    // The base and the anchor hold the body: traction − tool − supports − foundation = 0.
    EXPECT_LT(r.force_imbalance.norm(), 1e-6 * F);
    EXPECT_NEAR(r.support_reaction.z(), F, 1e-4 * F);
  }
}

/// The zmax triangles whose centroid lies over the central square [L/4, 3L/4]² of the top.
void add_top_patch(TetMesh& mesh, double L) {
  const SurfaceGroup* top = mesh.find_surface_group("zmax");
  SurfaceGroup patch;
  patch.name = "patch";
  std::vector<Eigen::Vector3i> rows;
  for (Eigen::Index f = 0; f < top->triangles.rows(); ++f) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int j = 0; j < 3; ++j) c += mesh.nodes.row(top->triangles(f, j)).transpose() / 3.0;
    if (std::abs(c.x() - 0.5 * L) < 0.25 * L && std::abs(c.y() - 0.5 * L) < 0.25 * L) rows.push_back(top->triangles.row(f));
  }
  patch.triangles.resize(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) patch.triangles.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  mesh.surface_groups.push_back(patch);
}

TEST(GraspFoundation, AStiffLayerRecoversTheRigidTie) {
  const double E = 1e6, nu = 0.3, L = 0.02, H = 0.01, pull = 0.5e-3, h = L / 4;
  FiniteStrainProblem base;
  base.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(L, L, H), 4, 4, 2);
  add_top_patch(base.mesh, L);
  ASSERT_EQ(base.mesh.find_surface_group("patch")->triangles.rows(), 8); // the four central cells
  base.materials.push_back({"body", LawKind::neo_hookean, E, nu});
  base.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  auto up = [pull](const Eigen::Vector3d&, double load) -> Eigen::Vector3d { return {0.0, 0.0, load * pull}; };
  auto solve = [](const FiniteStrainProblem& p) {
    FiniteStrainSolver solver(p, SolverSettings{});
    EquilibriumReport r;
    for (int step = 1; step <= 2; ++step) {
      r = solver.solve({step / 2.0, Eigen::Vector3d::Zero()});
      EXPECT_TRUE(r.converged) << r.failure;
    }
    return r;
  };
  FiniteStrainProblem tied = base;
  tied.displacement_boundaries.push_back({"patch", DisplacementBoundary::Kind::prescribed, up, {true, true, true}});
  const EquilibriumReport rt = solve(tied);
  const Eigen::Vector3d F_tied = rt.boundary_reactions.back().force;
  ASSERT_LT(F_tied.z(), 0.0); // the body holds the tie back
  double previous = 0.0;
  for (const double k : {1e2 * E / h, 1e3 * E / h, 1e4 * E / h}) {
    SCOPED_TRACE(k);
    FiniteStrainProblem compliant = base;
    compliant.foundations.push_back({"patch", k, up, {}}); // {}: a uniform layer
    const EquilibriumReport rc = solve(compliant);
    const double difference = (rc.foundation_forces[0] - F_tied).norm() / F_tied.norm();
    EXPECT_LT(rc.foundation_forces[0].norm(), F_tied.norm()); // a compliant grasp is softer
    if (previous > 0.0) {
      EXPECT_GT(previous / difference, 7.0); // order 1/k: tenfold k, about a tenth of the difference
      EXPECT_LT(previous / difference, 13.0);
    }
    previous = difference;
    EXPECT_LT((rc.force_imbalance).norm(), 1e-6 * F_tied.norm());
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(GraspFoundation, BadInputIsRefusedByName) {
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 0.01, 0.01), 1, 1, 1);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e6, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  auto zero = [](const Eigen::Vector3d&, double) -> Eigen::Vector3d { return Eigen::Vector3d::Zero(); };
  FiniteStrainProblem unknown = p, soft = p;
  unknown.foundations.push_back({"nowhere", 1e9, zero, {}});
  soft.foundations.push_back({"zmax", 0.0, zero, {}});
  for (const FiniteStrainProblem* bad : {&unknown, &soft}) {
    try {
      FiniteStrainSolver solver(*bad, SolverSettings{});
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("elastic foundation"), std::string::npos) << e.what();
    }
  }
}

} // namespace
} // namespace kerf::reference
