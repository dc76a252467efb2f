#include "particle_selection.hpp"

#include <vtkCellArray.h>
#include <vtkIdTypeArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace basalt::view {

CutPlane cut_plane(vtkPolyData& pd, const Cut& cut, const ViewDirection& view) {
  double b[6];
  pd.GetBounds(b);
  CutPlane c;
  c.axis = cut.axis;
  c.value = cut.value.value_or(0.5 * (b[2 * c.axis] + b[2 * c.axis + 1]));
  c.keep_below = view.toward_camera[static_cast<std::size_t>(c.axis)] >= 0;
  return c;
}

std::vector<vtkIdType> cut_indices(vtkPolyData& pd, const Cut& cut, const ViewDirection& view) {
  const CutPlane plane = cut_plane(pd, cut, view);
  std::vector<vtkIdType> kept;
  const vtkIdType n = pd.GetNumberOfPoints();
  kept.reserve(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
    if (plane.keeps(pd.GetPoint(i)[plane.axis])) kept.push_back(i);
  return kept;
}

std::vector<vtkIdType> drop_buried(vtkPolyData& pd, const std::vector<vtkIdType>& indices, double cell) {
  if (indices.empty() || !(cell > 0)) return indices;
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (vtkIdType i : indices) {
    const double* p = pd.GetPoint(i);
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], p[d]);
      hi[d] = std::max(hi[d], p[d]);
    }
  }
  std::int64_t dims[3];
  double cells = 1;
  for (int d = 0; d < 3; ++d) {
    dims[d] = static_cast<std::int64_t>(std::floor((hi[d] - lo[d]) / cell)) + 1;
    cells *= static_cast<double>(dims[d]);
  }
  if (cells > 64e6) return indices;
  auto cell_of = [&](const double* p, int d) {
    return std::min<std::int64_t>(dims[d] - 1, static_cast<std::int64_t>((p[d] - lo[d]) / cell));
  };
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(cells), 0);
  auto at = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::size_t>((k * dims[1] + j) * dims[0] + i);
  };
  for (vtkIdType i : indices) {
    const double* p = pd.GetPoint(i);
    occupied[at(cell_of(p, 0), cell_of(p, 1), cell_of(p, 2))] = 1;
  }
  std::vector<vtkIdType> kept;
  kept.reserve(indices.size() / 4);
  for (vtkIdType idx : indices) {
    const double* p = pd.GetPoint(idx);
    const std::int64_t c[3] = {cell_of(p, 0), cell_of(p, 1), cell_of(p, 2)};
    bool buried = true;
    // Within one cell of the cloud's bounding box: on its surface (or on the cut face). The last
    // cell along an axis may be thin, so this is a distance test, not an index test.
    for (int d = 0; d < 3 && buried; ++d)
      if (p[d] - lo[d] < cell || hi[d] - p[d] < cell) buried = false;
    for (int d = 0; d < 3 && buried; ++d)
      if (c[d] == 0 || c[d] == dims[d] - 1) buried = false;
    for (std::int64_t k = c[2] - 1; k <= c[2] + 1 && buried; ++k)
      for (std::int64_t j = c[1] - 1; j <= c[1] + 1 && buried; ++j)
        for (std::int64_t i = c[0] - 1; i <= c[0] + 1 && buried; ++i)
          if (!occupied[at(i, j, k)]) buried = false;
    if (!buried) kept.push_back(idx);
  }
  return kept;
}

vtkSmartPointer<vtkPolyData> select_points(vtkPolyData& pd, const std::vector<vtkIdType>& indices) {
  const auto m = static_cast<vtkIdType>(indices.size());
  auto out = vtkSmartPointer<vtkPolyData>::New();
  auto pts = vtkSmartPointer<vtkPoints>::New();
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(m);
  out->GetPointData()->CopyAllocate(pd.GetPointData(), m);
  for (vtkIdType k = 0; k < m; ++k) {
    const vtkIdType i = indices[static_cast<std::size_t>(k)];
    pts->SetPoint(k, pd.GetPoint(i));
    out->GetPointData()->CopyData(pd.GetPointData(), i, k);
  }
  out->SetPoints(pts);
  // One vertex per particle: the sphere mapper draws vertex cells.
  auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
  auto connectivity = vtkSmartPointer<vtkIdTypeArray>::New();
  offsets->SetNumberOfTuples(m + 1);
  connectivity->SetNumberOfTuples(m);
  for (vtkIdType k = 0; k <= m; ++k) offsets->SetValue(k, k);
  for (vtkIdType k = 0; k < m; ++k) connectivity->SetValue(k, k);
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  verts->SetData(offsets, connectivity);
  out->SetVerts(verts);
  return out;
}

}  // namespace basalt::view
