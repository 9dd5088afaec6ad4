#pragma once
// A ParaView collection (.pvd) of unstructured-grid steps with point data "displacement", as the
// reference run writes it (fields.pvd + fields/step_NNNN.vtu, experiments/reference_run/reference_run.cpp)
// or a model writes its own (the spring network's springs.pvd + springs/frame_NNNN.vtu,
// experiments/models/springs_builder.cpp): the times, and each step read on demand (VTK's XML parser
// and reader) at its deformed positions.

#include <vtkDataSet.h>
#include <vtkSmartPointer.h>

#include <filesystem>
#include <map>
#include <vector>

namespace kerf {

/// What the points of a series' .vtu files are. `rest`: the rest positions X, the deformed ones
/// being x = X + u (deal.II's DataOut on the reference mapping: the reference's fields.pvd).
/// `deformed`: the deformed positions x themselves, u = x − X written as data beside them (the
/// spring network's springs.pvd, docs/spring-network.md: it opens in ParaView deformed). Warping a
/// `deformed` series by u again would double every displacement.
enum class SeriesPoints { rest, deformed };

class PvdSeries {
public:
  /// Parses `pvd` whose steps hold `points` (throws std::runtime_error naming the file on a
  /// malformed one or one without DataSet entries).
  PvdSeries(const std::filesystem::path& pvd, SeriesPoints points);

  [[nodiscard]] const std::vector<double>& times() const { return m_times; }
  /// Index of the last step at or before `t` (the first step for an earlier t).
  [[nodiscard]] std::size_t step_at(double t) const;
  /// Step k at its deformed positions (points + "displacement" for a `rest` series, the points as
  /// written for a `deformed` one), with the file's point and cell data. Read once and kept. Throws std::runtime_error naming the .vtu if it cannot be read or
  /// lacks "displacement".
  vtkDataSet* deformed(std::size_t k);

private:
  std::filesystem::path m_pvd;
  SeriesPoints m_points;
  std::vector<double> m_times;
  std::vector<std::filesystem::path> m_files;
  std::map<std::size_t, vtkSmartPointer<vtkDataSet>> m_cache;
};

} // namespace kerf
