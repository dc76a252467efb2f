#pragma once
// Picking the per-particle quantity that colours the spheres, and the units it carries.
#include <vtkDoubleArray.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

#include "basalt/io/geometry.hpp"
#include "render_types.hpp"

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

/// The colour map's range and how it was chosen, for the colour bar's caption.
struct ColourScale {
  Range range;              ///< what the map spans; values outside are drawn in its end colours
  double min = 0, max = 0;  ///< the true extremes of the values it was chosen from (finite ones)
  std::string how;          ///< "p1-p99, clamped", "full range", "--range, clamped"
};

/// The default colour range: the 1st to 99th percentile of `values` (every drawn particle of every
/// frame drawn together), so that a handful of outliers (fast particles at a free surface) does not
/// squeeze the rest into one shade. Falls back to the full range when the two percentiles coincide,
/// and pads a constant field so that it sits in the middle of the map. Non-finite values are ignored.
/// Throws std::invalid_argument when no value is finite.
ColourScale robust_scale(std::vector<double> values);
/// `given` (from --range) with the true extremes of `values`.
ColourScale given_scale(const Range& given, const std::vector<double>& values);

}  // namespace basalt::view
