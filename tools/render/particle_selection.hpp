#pragma once
// Choosing which particles to draw: the half kept by a cut plane, and the particles that can be
// seen at all (a dense packing hides its interior; drawing it only costs time).
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <vector>

#include "render_types.hpp"

namespace basalt::view {

/// The cut plane of a frame: axis, where it sits (cut.value or the middle of the particles' bounding
/// box) and which side is kept (the far side as seen from `view`, so the cut face looks at the camera).
struct CutPlane {
  int axis = 0;
  double value = 0;
  bool keep_below = true;
  bool keeps(double coordinate) const { return keep_below ? coordinate <= value : coordinate >= value; }
};
CutPlane cut_plane(vtkPolyData& pd, const Cut& cut, const ViewDirection& view);

/// Indices of the particles on the far side of the cut plane as seen from `view` (so the cut face
/// looks at the camera); the plane sits at cut.value or the middle of the bounding box.
std::vector<vtkIdType> cut_indices(vtkPolyData& pd, const Cut& cut, const ViewDirection& view);

/// Drops particles buried in the packing: those whose cell of a grid with spacing `cell` (2 x the
/// largest radius) and all 26 neighbouring cells hold particles, so that at least `cell` of packing
/// lies between them and any empty space or the edge of the cloud. The camera is outside the cloud,
/// so such particles are hidden behind others. Returns `indices` unchanged when the grid would be
/// too large (sparse, scattered particles).
std::vector<vtkIdType> drop_buried(vtkPolyData& pd, const std::vector<vtkIdType>& indices, double cell);

/// A new polydata with the given points and all their point arrays, one vertex cell each.
vtkSmartPointer<vtkPolyData> select_points(vtkPolyData& pd, const std::vector<vtkIdType>& indices);

}  // namespace basalt::view
