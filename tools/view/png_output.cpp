#include "png_output.hpp"

#include <fmt/format.h>
#include <vtkPNGWriter.h>
#include <vtkSmartPointer.h>
#include <vtkWindowToImageFilter.h>

#include <stdexcept>
#include <system_error>

namespace basalt::view {

namespace fs = std::filesystem;

void write_png(vtkRenderWindow& window, const fs::path& file) {
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(&window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  const fs::path tmp = fs::path(file.string() + ".partial");
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetInputConnection(grab->GetOutputPort());
  writer->SetFileName(tmp.c_str());
  writer->SetCompressionLevel(9);
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !fs::exists(tmp, ec) || fs::file_size(tmp, ec) == 0) {
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write {}: the PNG writer failed", file.string()));
  }
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write {}: {}", file.string(), ec.message()));
  }
}

}  // namespace basalt::view
