// The fields of the current state to a .vtu (step-44's output_results; FiniteStrainSolver::
// write_fields): the displacement, J, the Cauchy stress and its von Mises value per output point,
// the contact pressure and material id per cell; distributed, one piece per process and a .pvtu.

#include "reference/solver/finite_strain_impl.hpp"

#include "meshes/atomic_file.hpp"

#include <deal.II/fe/fe_values.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <fstream>
#include <functional>
#include <stdexcept>

namespace kerf::reference {

namespace {

// Pointwise J, von Mises and Cauchy stress components from the displacement gradient.
class StressPostprocessor final : public dealii::DataPostprocessor<3> {
public:
  explicit StressPostprocessor(const std::vector<std::unique_ptr<HyperelasticLaw>>& laws) : m_laws(laws) {}
  void evaluate_vector_field(const dealii::DataPostprocessorInputs::Vector<3>& in,
                             std::vector<dealii::Vector<double>>& out) const override {
    const auto cell = in.template get_cell<3>();
    const HyperelasticLaw& law = *m_laws[cell->material_id()];
    for (std::size_t q = 0; q < in.solution_gradients.size(); ++q) {
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (unsigned c = 0; c < 3; ++c)
        for (unsigned d = 0; d < 3; ++d) F(c, d) += in.solution_gradients[q][c][d];
      const double J = F.determinant();
      out[q] = 0.0;
      out[q][0] = J;
      if (!(J > 0.0)) continue;
      const Eigen::Matrix3d sigma = cauchy_stress(F, law.stress_and_tangent(F).first_piola);
      out[q][1] = von_mises(sigma);
      const int idx[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
      for (int k = 0; k < 6; ++k) out[q][2 + static_cast<unsigned>(k)] = sigma(idx[k][0], idx[k][1]);
    }
  }
  std::vector<std::string> get_names() const override {
    return {"J", "von_mises", "sigma_xx", "sigma_yy", "sigma_zz", "sigma_xy", "sigma_yz", "sigma_xz"};
  }
  dealii::UpdateFlags get_needed_update_flags() const override { return dealii::update_gradients; }

private:
  const std::vector<std::unique_ptr<HyperelasticLaw>>& m_laws;
};

} // namespace

void FiniteStrainSolver::write_fields(const std::filesystem::path& file, const LoadState& load) const {
  const Impl& m = *m_impl;
  m.with_algebra([&](const auto& la) { m.write_fields(la.ghosted(la.u), file, load); });
}

template <class VectorType>
void FiniteStrainSolver::Impl::write_fields(const VectorType& u, const std::filesystem::path& file,
                                            const LoadState& load) const {
  const Impl& m = *this;
  const unsigned cells = m.dof.get_triangulation().n_active_cells(); // distributed: this process's view
  // Contact pressure per cell: the largest ε_N p over the cell's boundary quadrature points.
  dealii::Vector<float> pressure(cells), material(cells);
  if (m.tool) {
    dealii::FEFaceValues<3> ffv(*m.mapping, *m.fe, *m.face_quadrature,
                                dealii::update_values | dealii::update_quadrature_points);
    std::vector<dealii::Tensor<1, 3>> face_u(m.face_quadrature->size());
    for (const auto& cell : m.dof.active_cell_iterators())
      for (const unsigned f : cell->face_indices()) {
        if (!cell->is_locally_owned() || !cell->face(f)->at_boundary()) continue;
        ffv.reinit(cell, f);
        ffv[dealii::FEValuesExtractors::Vector(0)].get_function_values(u, face_u);
        for (unsigned q = 0; q < ffv.n_quadrature_points; ++q) {
          const Eigen::Vector3d x =
              to_eigen(ffv.quadrature_point(q)) + Eigen::Vector3d(face_u[q][0], face_u[q][1], face_u[q][2]);
          const ToolContactPoint c = tool_contact(*m.tool, load.tool_position, x, m.crack_side(cell, f));
          if (c.inside)
            pressure[cell->active_cell_index()] =
                std::max(pressure[cell->active_cell_index()], static_cast<float>(m.penalty * c.penetration));
        }
      }
  }
  for (const auto& cell : m.dof.active_cell_iterators())
    material[cell->active_cell_index()] = static_cast<float>(cell->material_id());
  StressPostprocessor stress(m.laws);
  dealii::DataOut<3> out;
  out.attach_dof_handler(m.dof);
  const std::vector<std::string> names(3, "displacement");
  const std::vector<dealii::DataComponentInterpretation::DataComponentInterpretation> kinds(
      3, dealii::DataComponentInterpretation::component_is_part_of_vector);
  out.add_data_vector(u, names, dealii::DataOut<3>::type_dof_data, kinds);
  out.add_data_vector(u, stress);
  out.add_data_vector(pressure, "contact_pressure", dealii::DataOut<3>::type_cell_data);
  out.add_data_vector(material, "material_id", dealii::DataOut<3>::type_cell_data);
  // Quadratic output cells without write_higher_order_cells (dealii-on-debian12.md, "output").
  // (Distributed: DataOut takes this process's locally owned cells.)
  out.build_patches(*m.mapping, static_cast<unsigned>(m.settings.degree));
  // deal.II reports a failed stream write (a full disk, a file-size limit) as an assertion that
  // names its own source line, not the file: the message gets the file's name here.
  auto write_or_name = [](const std::filesystem::path& target, std::ostream& stream,
                          const std::function<void(std::ostream&)>& body) {
    try {
      body(stream);
      stream.flush();
    } catch (const std::exception& e) {
      // deal.II's message: a rule of dashes, then lines; one line of single spaces here.
      std::string why;
      for (const char c : std::string(e.what())) {
        const char d = c == '\n' || c == '\t' ? ' ' : c;
        if ((d == ' ' || d == '-') && (why.empty() || why.back() == ' ')) continue;
        why.push_back(d);
      }
      throw std::runtime_error("write_fields: writing " + target.string() +
                               " failed (disk full or file-size limit?): " + why.substr(0, 400));
    }
    if (!stream) throw std::runtime_error("write_fields: writing " + target.string() + " failed (disk full or file-size limit?)");
  };
  if (!m.distributed) {
    std::ofstream stream(file);
    if (!stream) throw std::runtime_error("write_fields: cannot open " + file.string());
    write_or_name(file, stream, [&](std::ostream& s) { out.write_vtu(s); });
    return;
  }
  // One .vtu piece per process beside the .pvtu record that lists them (written by rank 0 after
  // every piece is in place), each atomically.
  auto piece = [&](int rank) { return file.stem().string() + "." + std::to_string(rank) + ".vtu"; };
  auto write = [&](const std::filesystem::path& target, const std::function<void(std::ostream&)>& body) {
    write_atomically(target, [&](const std::filesystem::path& tmp) {
      std::ofstream stream(tmp);
      if (!stream) throw std::runtime_error("write_fields: cannot open " + tmp.string());
      write_or_name(tmp, stream, body);
    });
  };
  write(file.parent_path() / piece(rank), [&](std::ostream& stream) { out.write_vtu(stream); });
  MPI_Barrier(parallel->comm);
  if (rank != 0) return;
  std::vector<std::string> pieces;
  for (int r = 0; r < process_count; ++r) pieces.push_back(piece(r));
  write(file, [&](std::ostream& stream) { out.write_pvtu_record(stream, pieces); });
}

} // namespace kerf::reference
