#pragma once
// A ParaView collection (.pvd) of unstructured-grid steps, as the reference run writes it
// (fields.pvd + fields/step_NNNN.vtu, experiments/run/reference_run.cpp): the times, and each
// step read on demand (VTK's XML parser and reader) and warped by its "displacement" field.

#include <vtkDataSet.h>
#include <vtkSmartPointer.h>

#include <filesystem>
#include <map>
#include <vector>

namespace kerf {

class PvdSeries {
public:
  /// Parses `pvd` (throws std::runtime_error naming the file on a malformed one or one without
  /// DataSet entries).
  explicit PvdSeries(const std::filesystem::path& pvd);

  [[nodiscard]] const std::vector<double>& times() const { return m_times; }
  /// Index of the last step at or before `t` (the first step for an earlier t).
  [[nodiscard]] std::size_t step_at(double t) const;
  /// Step k at its deformed positions (points + "displacement"), with the file's point and cell
  /// data. Read once and kept. Throws std::runtime_error naming the .vtu if it cannot be read or
  /// lacks "displacement".
  vtkDataSet* deformed(std::size_t k);

private:
  std::filesystem::path m_pvd;
  std::vector<double> m_times;
  std::vector<std::filesystem::path> m_files;
  std::map<std::size_t, vtkSmartPointer<vtkDataSet>> m_cache;
};

} // namespace kerf
