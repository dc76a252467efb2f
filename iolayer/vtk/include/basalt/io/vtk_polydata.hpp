#pragma once
// Conversion between Basalt's particle arrays and vtkPolyData (points = positions, one vertex cell
// per particle, point data id/radius/tag/velocity/speed/mass/displacement, field data for the clock).
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <filesystem>

#include "basalt/io/vtk_frames.hpp"

namespace basalt::io {

/// With `layout`, the point data holds exactly those arrays: an empty `a` gets empty arrays of each;
/// a non-empty `a` whose arrays differ from the layout throws std::invalid_argument.
vtkSmartPointer<vtkPolyData> to_polydata(const ParticleArrays& a, const FrameInfo& info,
                                         const std::vector<ArrayLayout>* layout = nullptr);

/// Reads a .vtp or .pvtp through VTK's readers. Throws FormatError naming the file when it is
/// missing, unreadable, or VTK reports an error.
vtkSmartPointer<vtkPolyData> read_polydata(const std::filesystem::path& file);

/// The clock and units stored in a polydata's field data by to_polydata (defaults when absent).
FrameInfo info_of(vtkPolyData& pd);

}  // namespace basalt::io
