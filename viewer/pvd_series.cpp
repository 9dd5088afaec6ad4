#include "viewer/pvd_series.hpp"

#include <vtkDataSet.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWarpVector.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <stdexcept>

namespace kerf {

namespace {

vtkXMLDataElement* find_child(vtkXMLDataElement* e, const char* name) {
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i)
    if (std::string(e->GetNestedElement(i)->GetName()) == name) return e->GetNestedElement(i);
  return nullptr;
}

} // namespace

PvdSeries::PvdSeries(const std::filesystem::path& pvd, SeriesPoints points) : m_pvd(pvd), m_points(points) {
  auto parser = vtkSmartPointer<vtkXMLDataParser>::New();
  parser->SetFileName(pvd.c_str());
  if (!std::filesystem::exists(pvd) || parser->Parse() == 0)
    throw std::runtime_error("viewer: cannot parse " + pvd.string() + " as XML");
  vtkXMLDataElement* root = parser->GetRootElement();
  vtkXMLDataElement* collection = root ? find_child(root, "Collection") : nullptr;
  if (!collection) throw std::runtime_error("viewer: " + pvd.string() + " has no <Collection>");
  std::vector<std::pair<double, std::filesystem::path>> steps;
  for (int i = 0; i < collection->GetNumberOfNestedElements(); ++i) {
    vtkXMLDataElement* d = collection->GetNestedElement(i);
    if (std::string(d->GetName()) != "DataSet") continue;
    double t = 0.0;
    const char* file = d->GetAttribute("file");
    if (!file || d->GetScalarAttribute("timestep", t) == 0)
      throw std::runtime_error("viewer: " + pvd.string() + ": a DataSet without file or timestep");
    steps.emplace_back(t, pvd.parent_path() / file);
  }
  if (steps.empty()) throw std::runtime_error("viewer: " + pvd.string() + " lists no DataSet");
  std::stable_sort(steps.begin(), steps.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [t, f] : steps) {
    m_times.push_back(t);
    m_files.push_back(f);
  }
}

std::size_t PvdSeries::step_at(double t) const {
  const auto it = std::upper_bound(m_times.begin(), m_times.end(), t + 1e-12);
  return it == m_times.begin() ? 0 : static_cast<std::size_t>(it - m_times.begin()) - 1;
}

vtkDataSet* PvdSeries::deformed(std::size_t k) {
  if (k >= m_files.size()) throw std::out_of_range("viewer: step " + std::to_string(k) + " of " + m_pvd.string());
  if (auto it = m_cache.find(k); it != m_cache.end()) return it->second;
  const std::filesystem::path& file = m_files[k];
  auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  if (!std::filesystem::exists(file) || !reader->CanReadFile(file.c_str()))
    throw std::runtime_error("viewer: cannot read " + file.string());
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  if (!grid || !grid->GetPointData()->GetArray("displacement"))
    throw std::runtime_error("viewer: " + file.string() + " has no point data \"displacement\"");
  vtkSmartPointer<vtkDataSet> out;
  if (m_points == SeriesPoints::deformed) { // x as written
    out.TakeReference(grid->NewInstance());
    out->DeepCopy(grid);
  } else { // x = X + u
    auto warp = vtkSmartPointer<vtkWarpVector>::New();
    warp->SetInputData(grid);
    warp->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "displacement");
    warp->SetScaleFactor(1.0);
    warp->Update();
    out.TakeReference(warp->GetOutput()->NewInstance());
    out->DeepCopy(warp->GetOutput());
  }
  m_cache[k] = out;
  return out;
}

} // namespace kerf
