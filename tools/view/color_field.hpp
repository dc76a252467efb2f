#pragma once
// Picking the per-particle quantity that colours the spheres, and the units it carries.
#include <vtkDoubleArray.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"

namespace basalt::view {

/// Names a frame can be coloured by: every point array, plus <vector>_x/_y/_z for 3-vectors
/// (a vector name alone means its magnitude).
std::vector<std::string> color_fields(vtkPolyData& pd);

/// The scalar values of `field` (a copy, one per point). Throws std::invalid_argument listing the
/// available fields when `field` is not one of them.
vtkSmartPointer<vtkDoubleArray> color_values(vtkPolyData& pd, const std::string& field);

/// Units of a field from the frame's units: radius -> "mm", speed -> "mm/ms", id -> "" ...
std::string field_units(const std::string& field, const io::Units& units);
/// "speed (mm/ms)", or "id" when the field has no unit.
std::string field_title(const std::string& field, const io::Units& units);

}  // namespace basalt::view
