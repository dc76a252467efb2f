#include "color_field.hpp"

#include <fmt/format.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "units.hpp"

namespace basalt::view {

namespace {

/// A 3-vector array and component (-1: magnitude) named by `field`, or nullptr.
vtkDataArray* find(vtkPolyData& pd, const std::string& field, int& component) {
  vtkPointData* p = pd.GetPointData();
  component = -1;
  if (vtkDataArray* a = p->GetArray(field.c_str())) return a;
  if (field.size() > 2 && field[field.size() - 2] == '_') {
    const char c = field.back();
    if (c == 'x' || c == 'y' || c == 'z') {
      vtkDataArray* a = p->GetArray(field.substr(0, field.size() - 2).c_str());
      if (a != nullptr && a->GetNumberOfComponents() == 3) {
        component = c - 'x';
        return a;
      }
    }
  }
  return nullptr;
}

/// Three scalar arrays <field>_x, <field>_y, <field>_z (a vector the frame stores by components, such as
/// the scene's angular_velocity_x/_y/_z), or false; also false with a <field>_w (a quaternion, such as
/// orientation, whose x, y, z part has no magnitude worth drawing).
bool components_of(vtkPolyData& pd, const std::string& field, vtkDataArray* c[3]) {
  if (pd.GetPointData()->GetArray((field + "_w").c_str()) != nullptr) return false;
  for (int k = 0; k < 3; ++k) {
    c[k] = pd.GetPointData()->GetArray((field + "_" + static_cast<char>('x' + k)).c_str());
    if (c[k] == nullptr || c[k]->GetNumberOfComponents() != 1) return false;
  }
  return true;
}

}  // namespace

std::vector<std::string> color_fields(vtkPolyData& pd) {
  std::vector<std::string> names;
  vtkPointData* p = pd.GetPointData();
  for (int i = 0; i < p->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = p->GetArray(i);
    if (a == nullptr || a->GetName() == nullptr) continue;
    const std::string name = a->GetName();
    if (a->GetNumberOfComponents() == 1) {
      names.push_back(name);
    } else if (a->GetNumberOfComponents() == 3) {
      names.push_back(name);
      for (const char* c : {"_x", "_y", "_z"}) names.push_back(name + c);
    }
  }
  // A vector stored as three scalar arrays: its magnitude under the common name.
  vtkDataArray* c[3];
  for (std::size_t i = 0, n = names.size(); i < n; ++i) {
    const std::string& name = names[i];
    if (name.size() > 2 && name.compare(name.size() - 2, 2, "_x") == 0) {
      const std::string base = name.substr(0, name.size() - 2);
      if (std::find(names.begin(), names.end(), base) == names.end() && components_of(pd, base, c))
        names.push_back(base);
    }
  }
  return names;
}

vtkSmartPointer<vtkDoubleArray> color_values(vtkPolyData& pd, const std::string& field) {
  int component = -1;
  vtkDataArray* a = find(pd, field, component);
  vtkDataArray* parts[3];
  if (a == nullptr && components_of(pd, field, parts)) {  // the magnitude of a vector stored by components
    auto out = vtkSmartPointer<vtkDoubleArray>::New();
    out->SetName(field.c_str());
    const vtkIdType n = parts[0]->GetNumberOfTuples();
    out->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i) {
      double s = 0;
      for (auto* p : parts) s += p->GetComponent(i, 0) * p->GetComponent(i, 0);
      out->SetValue(i, std::sqrt(s));
    }
    return out;
  }
  if (a == nullptr) {
    std::string hint;
    if (field == "displacement")
      hint = " (displacement needs --reference <initial geometry or checkpoint>)";
    else if (field == "speed" || field == "velocity")
      hint = " (a geometry has no velocities: give a checkpoint)";
    throw std::invalid_argument(fmt::format("unknown colour field \"{}\"{}; available: {}", field, hint,
                                            fmt::join(color_fields(pd), ", ")));
  }
  auto out = vtkSmartPointer<vtkDoubleArray>::New();
  out->SetName(field.c_str());
  const vtkIdType n = a->GetNumberOfTuples();
  out->SetNumberOfTuples(n);
  const int nc = a->GetNumberOfComponents();
  for (vtkIdType i = 0; i < n; ++i) {
    if (component >= 0) {
      out->SetValue(i, a->GetComponent(i, component));
    } else if (nc == 1) {
      out->SetValue(i, a->GetComponent(i, 0));
    } else {
      double s = 0;
      for (int c = 0; c < nc; ++c) s += a->GetComponent(i, c) * a->GetComponent(i, c);
      out->SetValue(i, std::sqrt(s));
    }
  }
  return out;
}

namespace {

std::vector<double> finite_only(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  return v;
}

/// Linear interpolation between the closest ranks of the sorted `v` (numpy's default).
double percentile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  const double f = pos - static_cast<double>(lo);
  return sorted[lo] + f * (sorted[hi] - sorted[lo]);
}

}  // namespace

ColourScale robust_scale(std::vector<double> values) {
  values = finite_only(std::move(values));
  if (values.empty()) throw std::invalid_argument("no finite value to colour by");
  std::sort(values.begin(), values.end());
  ColourScale s;
  s.min = values.front();
  s.max = values.back();
  s.range = {percentile(values, 0.01), percentile(values, 0.99)};
  s.how = "p1-p99, clamped";
  if (!(s.range.min < s.range.max)) {
    s.range = {s.min, s.max};
    s.how = "full range";
  }
  if (!(s.range.min < s.range.max)) {  // a constant field: centre it in the map
    const double pad = s.min == 0 ? 1.0 : 0.05 * std::abs(s.min);
    s.range = {s.min - pad, s.max + pad};
  }
  return s;
}

ColourScale given_scale(const Range& given, const std::vector<double>& values) {
  ColourScale s;
  s.range = given;
  s.how = "--range, clamped";
  const std::vector<double> v = finite_only(values);
  if (!v.empty()) {
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    s.min = *lo;
    s.max = *hi;
  }
  return s;
}

std::string field_units(const std::string& field, const io::Units& units) {
  std::string base = field;
  if (base.size() > 2 && base[base.size() - 2] == '_' &&
      (base.back() == 'x' || base.back() == 'y' || base.back() == 'z'))
    base = base.substr(0, base.size() - 2);
  return quantity_units(base, units);
}

std::string field_title(const std::string& field, const io::Units& units) {
  const std::string u = field_units(field, units);
  return u.empty() ? field : fmt::format("{} ({})", field, u);
}

}  // namespace basalt::view
