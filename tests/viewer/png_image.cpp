#include "tests/viewer/png_image.hpp"

#include <vtkImageData.h>
#include <vtkPNGReader.h>
#include <vtkSmartPointer.h>

#include <cstdlib>
#include <stdexcept>

namespace kerf::test {

PngImage PngImage::read(const std::filesystem::path& file) {
  auto reader = vtkSmartPointer<vtkPNGReader>::New();
  if (!std::filesystem::exists(file) || !reader->CanReadFile(file.c_str()))
    throw std::runtime_error("not a readable PNG: " + file.string());
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  const int channels = image->GetNumberOfScalarComponents();
  if (channels < 3) throw std::runtime_error("not an RGB PNG: " + file.string());
  PngImage out;
  out.width = dims[0];
  out.height = dims[1];
  out.rgb.resize(static_cast<std::size_t>(out.width) * out.height * 3);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      for (int c = 0; c < 3; ++c)
        out.rgb[3 * (static_cast<std::size_t>(y) * out.width + x) + c] =
            static_cast<std::uint8_t>(image->GetScalarComponentAsDouble(x, y, 0, c));
  return out;
}

int PngImage::difference(const PngImage& other, int x, int y) const {
  const std::uint8_t* a = at(x, y);
  const std::uint8_t* b = other.at(x, y);
  int d = 0;
  for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(static_cast<int>(a[c]) - static_cast<int>(b[c])));
  return d;
}

} // namespace kerf::test
