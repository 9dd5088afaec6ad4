// The load path's cut-back (reference/load_path.hpp): an increment too large for the Newton
// budget is bisected and the path recovers to the same equilibrium as a finely stepped solve
// (hyperelasticity is path-independent: the discrete equilibrium at a given load does not depend
// on the steps that reached it); when the cut-backs are exhausted the path stops naming the
// sample, and the solver keeps the last converged state.

#include "reference/finite_strain_solver.hpp"
#include "reference/load_path.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <gtest/gtest.h>

namespace kerf::reference {
namespace {

/// A 20 mm cube, bonded at z = 0, its top face pulled up by load × 40% of the height.
FiniteStrainProblem stretched_cube() {
  const double H = 0.02;
  FiniteStrainProblem p;
  p.mesh = test::named_box(Eigen::Vector3d::Zero(), Eigen::Vector3d(H, H, H), 2, 2, 2);
  p.materials.push_back({"body", LawKind::neo_hookean, 1e5, 0.3});
  p.displacement_boundaries.push_back({"zmin", DisplacementBoundary::Kind::bonded, {}, {}});
  p.displacement_boundaries.push_back({"zmax", DisplacementBoundary::Kind::prescribed,
                                       [H](const Eigen::Vector3d&, double load) {
                                         return Eigen::Vector3d(0.0, 0.0, 0.4 * H * load);
                                       },
                                       {true, true, true}});
  return p;
}

TEST(LoadPath, CutsBackAnOverLargeIncrementAndRecovers) {
  const FiniteStrainProblem p = stretched_cube();
  SolverSettings tight;
  tight.max_newton_iterations = 3; // too few for the whole 40% stretch in one increment
  FiniteStrainSolver solver(p, tight);
  LoadPath path(solver, LoadState{});
  const LoadStepReport r = path.advance({LoadState{1.0, Eigen::Vector3d::Zero()}, 7, 0.25});
  EXPECT_TRUE(r.converged);
  EXPECT_GE(r.cutbacks, 1);
  EXPECT_LE(r.cutbacks, 6);
  EXPECT_GT(r.increments, 1);
  EXPECT_DOUBLE_EQ(path.last_converged_load().load_factor, 1.0);

  // Independent second solve: the default Newton budget, 20 equal load steps.
  FiniteStrainSolver fine(p, SolverSettings{});
  EquilibriumReport f;
  for (int k = 1; k <= 20; ++k) {
    f = fine.solve({0.05 * k, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(f.converged) << f.failure;
  }
  const Eigen::Vector3d X(0.01, 0.01, 0.01); // the cube's centre
  EXPECT_LT((solver.displacement_at(X) - fine.displacement_at(X)).norm(), 1e-9 * fine.displacement_at(X).norm());
  EXPECT_LT((r.support_reaction - f.support_reaction).norm(), 1e-6 * f.support_reaction.norm() + 1e-12);
}

TEST(LoadPath, StopsNamingTheSampleAndKeepsTheLastConvergedState) {
  const FiniteStrainProblem p = stretched_cube();
  SolverSettings one;
  one.max_newton_iterations = 1; // one Newton step never meets 1e-9 on a nonlinear increment
  FiniteStrainSolver solver(p, one);
  LoadPath path(solver, LoadState{}, LoadPathSettings{2});
  const std::vector<double> before = solver.state();
  try {
    path.advance({LoadState{1.0, Eigen::Vector3d::Zero()}, 12, 0.375});
    FAIL() << "the load path did not stop";
  } catch (const LoadPathError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.sample(), 12u);
    EXPECT_DOUBLE_EQ(e.time(), 0.375);
    EXPECT_NE(what.find("sample 12 (t = 0.375 s)"), std::string::npos) << what;
    EXPECT_NE(what.find("after 2 cut-backs"), std::string::npos) << what;
    EXPECT_NE(what.find("residual history"), std::string::npos) << what;
    EXPECT_NE(what.find("last converged state"), std::string::npos) << what;
  }
  EXPECT_EQ(solver.state(), before);
  EXPECT_EQ(path.last_converged_state(), before);
  EXPECT_THROW((void)LoadPath(solver, LoadState{}, LoadPathSettings{-1}), std::invalid_argument);
}

// A NaN in the residual (reference::SolverSettings::residual_fault; docs/reliability.md) is a failed solve:
// never "converged" (a NaN compares false with every tolerance, so a convergence test written the
// other way round would pass it), the state restored; the load path cuts back and, once the fault
// is gone, reaches the equilibrium a clean solver reaches (path independence, as above).
TEST(LoadPath, NaNInTheResidualIsAFailedSolveAndIsCutBack) {
  const FiniteStrainProblem p = stretched_cube();
  SolverSettings faulty;
  int calls = 0;
  faulty.residual_fault = [&calls](const LoadState&, int) {
    ++calls;
    return calls <= 2; // the first assembly of the lone solve and of the path's first attempt
  };
  FiniteStrainSolver solver(p, faulty);
  const std::vector<double> before = solver.state();
  const EquilibriumReport failed = solver.solve({0.1, Eigen::Vector3d::Zero()});
  EXPECT_FALSE(failed.converged);
  EXPECT_NE(failed.failure.find("non-finite residual"), std::string::npos) << failed.failure;
  EXPECT_EQ(solver.state(), before);

  LoadPath path(solver, LoadState{});
  const LoadStepReport r = path.advance({LoadState{1.0, Eigen::Vector3d::Zero()}, 3, 0.5});
  ASSERT_TRUE(r.converged);
  EXPECT_GE(r.cutbacks, 1); // the poisoned first attempt
  FiniteStrainSolver clean(p, SolverSettings{});
  EquilibriumReport f;
  for (int k = 1; k <= 20; ++k) {
    f = clean.solve({0.05 * k, Eigen::Vector3d::Zero()});
    ASSERT_TRUE(f.converged) << f.failure;
  }
  const Eigen::Vector3d X(0.01, 0.01, 0.01);
  EXPECT_LT((solver.displacement_at(X) - clean.displacement_at(X)).norm(), 1e-9 * clean.displacement_at(X).norm());
}

// Between two targets the load path follows the motion it is given (reference/load_path.hpp): the
// sub-loads of a cut-back are the motion at their own time, not points of the chord between the
// two targets. The motion here turns a corner half way (the tool goes 2 mm along x, then 2 mm back
// along y) while the cube's top is stretched by the load factor t: every load the solver is asked
// to solve (seen through the residual hook, which receives it) lies on the motion, and the cut-back
// that halves the increment asks for the corner itself, (2, 0, 0) mm, not the chord's midpoint
// (1, 1, 0) mm.
TEST(LoadPath, CutBacksFollowTheMotionNotTheChord) {
  const FiniteStrainProblem p = stretched_cube();
  const auto motion = [](double t) {
    const Eigen::Vector3d corner(2e-3, 0.0, 0.0);
    const Eigen::Vector3d at = t <= 0.5 ? Eigen::Vector3d(corner * (t / 0.5)) : Eigen::Vector3d(corner + Eigen::Vector3d(0.0, 2e-3, 0.0) * ((t - 0.5) / 0.5));
    return LoadState{t, at, t};
  };
  std::vector<LoadState> asked;
  SolverSettings tight;
  tight.max_newton_iterations = 3; // too few for the whole 40% stretch in one increment: it is cut back
  tight.residual_fault = [&asked](const LoadState& load, int iteration) {
    if (iteration == 0) asked.push_back(load);
    return false;
  };
  FiniteStrainSolver solver(p, tight);
  LoadPath path(solver, motion(0.0), LoadPathSettings{}, motion);
  const LoadStepReport r = path.advance({motion(1.0), 1, 1.0});
  ASSERT_TRUE(r.converged);
  ASSERT_GE(r.cutbacks, 1);
  bool corner_asked = false;
  for (const LoadState& load : asked) {
    EXPECT_LT((load.tool_position - motion(load.time).tool_position).norm(), 1e-15) << "t = " << load.time;
    EXPECT_NEAR(load.load_factor, load.time, 1e-15);
    corner_asked = corner_asked || std::abs(load.time - 0.5) < 1e-12;
  }
  EXPECT_TRUE(corner_asked);
  // Without a motion the same cut-back interpolates the chord: its half-way load is (1, 1, 0) mm.
  asked.clear();
  FiniteStrainSolver chord_solver(p, tight);
  LoadPath chord(chord_solver, motion(0.0));
  ASSERT_TRUE(chord.advance({motion(1.0), 1, 1.0}).converged);
  bool chord_midpoint = false;
  for (const LoadState& load : asked)
    chord_midpoint = chord_midpoint || (load.tool_position - Eigen::Vector3d(1e-3, 1e-3, 0.0)).norm() < 1e-15;
  EXPECT_TRUE(chord_midpoint);
}

} // namespace
} // namespace kerf::reference
