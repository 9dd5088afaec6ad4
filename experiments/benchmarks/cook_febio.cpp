// Cook's membrane on gmsh meshes, for kerf and FEBio side by side (experiments/benchmarks/febio_cook.sh).
//
//   cook_febio mesh H DIR   meshes cook/cook_membrane.geo with element size H [mm] (first-order
//                           tetrahedra, one layer through the 1 mm thickness) and writes
//                           DIR/cook_hH.msh (kerf's input) and DIR/cook_hH.feb (FEBio's: the same
//                           mesh as quadratic tetrahedra, tet10 with straight edges, which is what
//                           kerf's P2 space builds on the .msh)
//   cook_febio solve MSH [--full-newton] [--steps N] [--tolerance REL] [--energy-line-search] [--verbose]
//                           kerf's P2 reference on that mesh: the code gallery's energy, dead load,
//                           N equal load steps (default 10); prints the tip displacement and the
//                           phase times.
//                           --full-newton: a tangent factorised at every iteration and no predictor
//                           (SolverSettings::quasi_newton and extrapolate_initial_guess off)
//                           --tolerance: SolverSettings::relative_tolerance (default 1e-9)
//                           --energy-line-search: LineSearch::energy (FEBio's line search)
//                           --verbose: each step's |R| history on stderr
//
// The problem (docs/reference.md, "Cook's membrane"): clamped at x = 0, u_z = 0 on both faces
// (plane strain), a dead-load shear of 1 N in total along +y on x = 48 mm; the code gallery's
// decoupled neo-Hookean ψ = μ/2 (Ī₁ − 3) + κ/4 (J² − 1 − 2 ln J), μ = 422.5 kPa, ν = 0.3, which is
// FEBio's Mooney–Rivlin with c₁ = μ/2, c₂ = 0, k = κ and the NIKE3D volumetric term. The tip is
// u_y at (48, 52, 0.5) mm.

#include "meshes/gmsh_io.hpp"
#include "meshes/tet_mesh.hpp"
#include "reference/finite_strain_solver.hpp"
#include "tests/reference/reference_test_meshes.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string>

using namespace kerf;
using namespace kerf::reference;

namespace {

constexpr double k_mu = 422.5e3, k_nu = 0.3; // [Pa]
const Eigen::Vector3d k_tip(48e-3, 52e-3, 0.5e-3);

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

std::string size_tag(double h_mm) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", h_mm);
  return buf;
}

/// FEBio 4.0 input: the mesh as tet10 (FEBio's node order: corners, then the midpoints of the
/// edges 01, 12, 20, 03, 13, 23), mm–N–MPa units.
void write_feb(const TetMesh& mesh, const std::filesystem::path& file) {
  std::map<std::pair<int, int>, int> midpoint; // edge (a < b) -> node index (0-based, after the vertices)
  std::vector<Eigen::Vector3d> nodes;
  for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v) nodes.emplace_back(mesh.nodes.row(v).transpose());
  auto mid = [&](int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    nodes.push_back(0.5 * (nodes[static_cast<std::size_t>(a)] + nodes[static_cast<std::size_t>(b)]));
    return midpoint.emplace(key, static_cast<int>(nodes.size()) - 1).first->second;
  };
  constexpr int edges[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  std::vector<std::array<int, 10>> tets;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    std::array<int, 10> e{};
    for (int k = 0; k < 4; ++k) e[static_cast<std::size_t>(k)] = mesh.tets(t, k);
    for (int k = 0; k < 6; ++k) e[static_cast<std::size_t>(4 + k)] = mid(mesh.tets(t, edges[k][0]), mesh.tets(t, edges[k][1]));
    tets.push_back(e);
  }
  auto group = [&](const char* name) -> const SurfaceGroup& {
    const SurfaceGroup* g = mesh.find_surface_group(name);
    if (g == nullptr) throw std::runtime_error(std::string("cook_febio: the mesh has no surface group ") + name);
    return *g;
  };
  // Node sets of the supports (the vertices and edge midpoints of their triangles).
  auto node_set = [&](std::initializer_list<const char*> names) {
    std::vector<int> ids;
    for (const char* n : names) {
      const SurfaceGroup& g = group(n);
      for (Eigen::Index f = 0; f < g.triangles.rows(); ++f)
        for (int a = 0; a < 3; ++a) {
          ids.push_back(g.triangles(f, a));
          ids.push_back(mid(g.triangles(f, a), g.triangles(f, (a + 1) % 3)));
        }
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    std::string out;
    for (const int i : ids) {
      if (!out.empty()) out += ',';
      out += std::to_string(i + 1);
    }
    return out;
  };
  const std::string xmin = node_set({"xmin"}), faces = node_set({"zmin", "zmax"});
  int tip = -1;
  for (std::size_t v = 0; v < nodes.size(); ++v)
    if ((nodes[v] - k_tip).norm() < 1e-9) tip = static_cast<int>(v);
  if (tip < 0) throw std::runtime_error("cook_febio: no node at the tip (48, 52, 0.5) mm");
  const SurfaceGroup& loaded = group("xmax");
  double area = 0.0;
  for (Eigen::Index f = 0; f < loaded.triangles.rows(); ++f) {
    const Eigen::Vector3d a = mesh.nodes.row(loaded.triangles(f, 0)), b = mesh.nodes.row(loaded.triangles(f, 1)),
                          c = mesh.nodes.row(loaded.triangles(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double kappa = 2.0 * k_mu * (1.0 + k_nu) / (3.0 * (1.0 - 2.0 * k_nu));
  std::ofstream out(file);
  if (!out) throw std::runtime_error("cook_febio: cannot write " + file.string());
  out.precision(17);
  out << "<?xml version=\"1.0\" encoding=\"ISO-8859-1\"?>\n"
      << "<!-- Cook's membrane, written by kerf's experiments/benchmarks/cook_febio from "
         "cook/cook_membrane.geo (gmsh); units mm, N, MPa. Tip node "
      << tip + 1 << " at (48, 52, 0.5) mm. -->\n"
      << "<febio_spec version=\"4.0\">\n  <Module type=\"solid\"/>\n  <Control>\n"
      << "    <analysis>STATIC</analysis>\n    <time_steps>10</time_steps>\n    <step_size>0.1</step_size>\n"
      << "    <solver type=\"solid\">\n      <optimize_bw>1</optimize_bw>\n"
      << "      <qn_method type=\"BFGS\"/>\n    </solver>\n  </Control>\n"
      << "  <Material>\n    <material id=\"1\" name=\"body\" type=\"Mooney-Rivlin\">\n"
      << "      <density>1</density>\n      <c1>" << 0.5 * k_mu * 1e-6 << "</c1>\n      <c2>0</c2>\n"
      << "      <k>" << kappa * 1e-6 << "</k>\n      <pressure_model>NIKE3D</pressure_model>\n"
      << "    </material>\n  </Material>\n  <Mesh>\n    <Nodes name=\"all\">\n";
  for (std::size_t v = 0; v < nodes.size(); ++v)
    out << "      <node id=\"" << v + 1 << "\">" << nodes[v].x() * 1e3 << "," << nodes[v].y() * 1e3 << ","
        << nodes[v].z() * 1e3 << "</node>\n";
  out << "    </Nodes>\n    <Elements type=\"tet10\" name=\"body\">\n";
  for (std::size_t t = 0; t < tets.size(); ++t) {
    out << "      <elem id=\"" << t + 1 << "\">";
    for (std::size_t k = 0; k < 10; ++k) out << (k ? "," : "") << tets[t][k] + 1;
    out << "</elem>\n";
  }
  out << "    </Elements>\n    <NodeSet name=\"xmin\">" << xmin << "</NodeSet>\n"
      << "    <NodeSet name=\"faces\">" << faces << "</NodeSet>\n    <Surface name=\"xmax\">\n";
  for (Eigen::Index f = 0; f < loaded.triangles.rows(); ++f) {
    const int a = loaded.triangles(f, 0), b = loaded.triangles(f, 1), c = loaded.triangles(f, 2);
    out << "      <tri6 id=\"" << f + 1 << "\">" << a + 1 << "," << b + 1 << "," << c + 1 << "," << mid(a, b) + 1 << ","
        << mid(b, c) + 1 << "," << mid(c, a) + 1 << "</tri6>\n";
  }
  out << "    </Surface>\n  </Mesh>\n  <MeshDomains>\n    <SolidDomain name=\"body\" mat=\"body\"/>\n  </MeshDomains>\n"
      << "  <Boundary>\n    <bc name=\"clamp\" node_set=\"xmin\" type=\"zero displacement\">\n"
      << "      <x_dof>1</x_dof>\n      <y_dof>1</y_dof>\n      <z_dof>1</z_dof>\n    </bc>\n"
      << "    <bc name=\"plane_strain\" node_set=\"faces\" type=\"zero displacement\">\n"
      << "      <x_dof>0</x_dof>\n      <y_dof>0</y_dof>\n      <z_dof>1</z_dof>\n    </bc>\n  </Boundary>\n"
      << "  <Loads>\n    <surface_load name=\"shear\" surface=\"xmax\" type=\"traction\">\n"
      << "      <scale lc=\"1\">1</scale>\n      <traction>0," << 1.0 / (area * 1e6) << ",0</traction>\n"
      << "      <linear>1</linear>\n    </surface_load>\n  </Loads>\n"
      << "  <LoadData>\n    <load_controller id=\"1\" name=\"ramp\" type=\"loadcurve\">\n"
      << "      <interpolate>LINEAR</interpolate>\n      <points>\n        <pt>0,0</pt>\n        <pt>1,1</pt>\n"
      << "      </points>\n    </load_controller>\n  </LoadData>\n"
      << "  <Output>\n    <logfile>\n      <node_data data=\"uy\" delim=\",\">" << tip + 1 << "</node_data>\n"
      << "    </logfile>\n  </Output>\n</febio_spec>\n";
  if (!out) throw std::runtime_error("cook_febio: writing " + file.string() + " failed");
}

struct SolveOptions {
  bool full_newton = false;
  int steps = 10;
  double relative_tolerance = SolverSettings{}.relative_tolerance;
  bool verbose = false; ///< each load step's |R| history on stderr
  LineSearch line_search = SolverSettings{}.line_search;
};

int solve(const std::filesystem::path& msh, const SolveOptions& o) {
  const double cpu0 = cpu_seconds();
  const auto wall0 = std::chrono::steady_clock::now();
  const FiniteStrainProblem p = test::cook_membrane_problem(read_msh(msh));
  SolverSettings settings;
  settings.degree = 2;
  settings.linear_solver = LinearSolverChoice::direct; // FEBio's skyline is direct too, at every size
  settings.quasi_newton = !o.full_newton;
  settings.extrapolate_initial_guess = !o.full_newton;
  settings.relative_tolerance = o.relative_tolerance;
  settings.line_search = o.line_search;
  FiniteStrainSolver solver(p, settings);
  const double setup = cpu_seconds() - cpu0;
  int its = 0, factorizations = 0;
  double assembly = 0.0, linear = 0.0;
  for (int step = 1; step <= o.steps; ++step) {
    const EquilibriumReport r = solver.solve({static_cast<double>(step) / o.steps, Eigen::Vector3d::Zero()});
    if (!r.converged) throw std::runtime_error("cook_febio: load step " + std::to_string(step) + " failed: " + r.failure);
    if (o.verbose) {
      std::fprintf(stderr, "step %d: %d iterations, %d factorisations, |R| [N]:", step, r.newton_iterations, r.factorizations);
      for (const double x : r.residual_history) std::fprintf(stderr, " %.2e", x);
      std::fprintf(stderr, "\n");
    }
    its += r.newton_iterations;
    factorizations += r.factorizations;
    assembly += r.assembly_seconds;
    linear += r.linear_solve_seconds;
  }
  const double tip = solver.displacement_at(k_tip).y();
  std::printf("kerf mesh=%s dofs=%zu tip_mm=%.9f newton=%d factorizations=%d setup_s=%.3f assembly_s=%.3f linear_s=%.3f cpu_s=%.3f wall_s=%.3f\n",
              msh.filename().string().c_str(), solver.dof_count(), tip * 1e3, its, factorizations, setup, assembly, linear,
              cpu_seconds() - cpu0, std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return 0;
}

} // namespace

int main(int argc, char** argv) try {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "mesh" && argc == 4) {
    const double h_mm = std::stod(argv[2]);
    const std::filesystem::path dir = argv[3];
    const std::filesystem::path geo = std::filesystem::path(KERF_SOURCE_DIR) / "experiments/benchmarks/cook/cook_membrane.geo";
    const TetMesh mesh = mesh_geo(geo, {}, h_mm * 1e-3);
    std::filesystem::create_directories(dir);
    const std::string stem = "cook_h" + size_tag(h_mm);
    write_msh(mesh, dir / (stem + ".msh"));
    write_feb(mesh, dir / (stem + ".feb"));
    std::printf("%s: %ld nodes, %ld tetrahedra\n", stem.c_str(), static_cast<long>(mesh.nodes.rows()),
                static_cast<long>(mesh.tets.rows()));
    return 0;
  }
  if (mode == "solve" && argc >= 3) {
    SolveOptions o;
    for (int a = 3; a < argc; ++a) {
      const std::string arg = argv[a];
      if (arg == "--full-newton") o.full_newton = true;
      else if (arg == "--steps" && a + 1 < argc) o.steps = std::stoi(argv[++a]);
      else if (arg == "--tolerance" && a + 1 < argc) o.relative_tolerance = std::stod(argv[++a]);
      else if (arg == "--verbose") o.verbose = true;
      else if (arg == "--energy-line-search") o.line_search = LineSearch::energy;
      else throw std::invalid_argument("solve: unknown option " + arg);
    }
    if (o.steps < 1 || !(o.relative_tolerance > 0.0)) throw std::invalid_argument("solve: --steps >= 1 and --tolerance > 0");
    return solve(argv[2], o);
  }
  std::cerr << "usage: cook_febio mesh H_MM DIR | cook_febio solve FILE.msh [--full-newton] [--steps N] "
               "[--tolerance REL] [--energy-line-search] [--verbose]\n";
  return 2;
} catch (const std::exception& e) {
  std::cerr << "cook_febio: " << e.what() << "\n";
  return 1;
}
