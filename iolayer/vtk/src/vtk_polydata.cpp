#include "basalt/io/vtk_polydata.hpp"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkStringArray.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLPPolyDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "vtk_errors.hpp"

namespace basalt::io {

namespace fs = std::filesystem;

namespace {

template <class VtkArray, class T>
vtkSmartPointer<VtkArray> make_array(const char* name, std::span<const T> values, int components) {
  auto arr = vtkSmartPointer<VtkArray>::New();
  arr->SetName(name);
  arr->SetNumberOfComponents(components);
  const auto tuples = static_cast<vtkIdType>(values.size() / static_cast<std::size_t>(components));
  arr->SetNumberOfTuples(tuples);
  if (!values.empty()) std::memcpy(arr->GetPointer(0), values.data(), values.size_bytes());
  return arr;
}

vtkSmartPointer<vtkDoubleArray> vec3_array(const char* name, std::span<const Vec3> v) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  return make_array<vtkDoubleArray>(name, std::span<const double>(v.data()->data(), 3 * v.size()), 3);
}

/// Makes the point data hold exactly `layout`'s arrays (see to_polydata).
void conform(vtkPointData& p, const ParticleArrays& a, const std::vector<ArrayLayout>& layout) {
  const std::vector<ArrayLayout> have = layout_of(a);
  if (have == layout) return;
  if (a.size() != 0) {
    std::string names;
    for (const auto& l : have) names += " " + l.name;
    std::string wanted;
    for (const auto& l : layout) wanted += " " + l.name;
    throw std::invalid_argument(
        fmt::format("piece arrays [{} ] differ from the frame layout [{} ]", names, wanted));
  }
  p.Initialize();
  for (const auto& l : layout) {
    vtkSmartPointer<vtkDataArray> arr;
    if (l.type == "Int64")
      arr = vtkSmartPointer<vtkTypeInt64Array>::New();
    else if (l.type == "Int32")
      arr = vtkSmartPointer<vtkTypeInt32Array>::New();
    else if (l.type == "Float64")
      arr = vtkSmartPointer<vtkDoubleArray>::New();
    else
      throw std::invalid_argument("unknown array type " + l.type);
    arr->SetName(l.name.c_str());
    arr->SetNumberOfComponents(l.components);
    p.AddArray(arr);
  }
}

}  // namespace

vtkSmartPointer<vtkPolyData> to_polydata(const ParticleArrays& a, const FrameInfo& info,
                                         const std::vector<ArrayLayout>* layout) {
  a.check();
  const auto n = static_cast<vtkIdType>(a.size());
  auto pd = vtkSmartPointer<vtkPolyData>::New();

  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetData(vec3_array("Points", a.position));
  pd->SetPoints(points);

  // One vertex cell per particle, so that ParaView's Surface/Points representations show them.
  auto offsets = vtkSmartPointer<vtkIdTypeArray>::New();
  auto connectivity = vtkSmartPointer<vtkIdTypeArray>::New();
  offsets->SetNumberOfTuples(n + 1);
  connectivity->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i) {
    offsets->SetValue(i, i);
    connectivity->SetValue(i, i);
  }
  offsets->SetValue(n, n);
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  verts->SetData(offsets, connectivity);
  pd->SetVerts(verts);

  vtkPointData* p = pd->GetPointData();
  p->AddArray(make_array<vtkTypeInt64Array>("id", a.id, 1));
  p->AddArray(make_array<vtkDoubleArray>("radius", a.radius, 1));
  p->AddArray(make_array<vtkTypeInt32Array>("tag", a.tag, 1));
  if (!a.mass.empty()) p->AddArray(make_array<vtkDoubleArray>("mass", a.mass, 1));
  if (!a.velocity.empty()) {
    p->AddArray(vec3_array("velocity", a.velocity));
    auto speed = vtkSmartPointer<vtkDoubleArray>::New();
    speed->SetName("speed");
    speed->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i) {
      const Vec3& v = a.velocity[static_cast<std::size_t>(i)];
      speed->SetValue(i, std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
    p->AddArray(speed);
  }
  if (!a.displacement.empty()) p->AddArray(vec3_array("displacement", a.displacement));
  for (const auto& [name, values] : a.fields)
    p->AddArray(make_array<vtkDoubleArray>(name.c_str(), values, 1));
  if (layout != nullptr) conform(*p, a, *layout);
  p->SetActiveScalars("radius");

  vtkFieldData* f = pd->GetFieldData();
  if (info.has_clock) {
    auto step = vtkSmartPointer<vtkTypeInt64Array>::New();
    step->SetName("step");
    step->InsertNextValue(info.step);
    f->AddArray(step);
    for (const char* name : {"time", "TimeValue"}) {  // TimeValue: ParaView's name for a frame's time
      auto t = vtkSmartPointer<vtkDoubleArray>::New();
      t->SetName(name);
      t->InsertNextValue(info.time);
      f->AddArray(t);
    }
  }
  auto units = vtkSmartPointer<vtkStringArray>::New();
  units->SetName("units");  // length, time, force
  units->InsertNextValue(info.units.length);
  units->InsertNextValue(info.units.time);
  units->InsertNextValue(info.units.force);
  f->AddArray(units);
  return pd;
}

FrameInfo info_of(vtkPolyData& pd) {
  FrameInfo info;
  vtkFieldData* f = pd.GetFieldData();
  if (f == nullptr) return info;
  auto* step = vtkDataArray::SafeDownCast(f->GetAbstractArray("step"));
  auto* time = vtkDataArray::SafeDownCast(f->GetAbstractArray("time"));
  if (step != nullptr && time != nullptr && step->GetNumberOfTuples() > 0 && time->GetNumberOfTuples() > 0) {
    info.has_clock = true;
    info.step = static_cast<std::int64_t>(step->GetTuple1(0));
    info.time = time->GetTuple1(0);
  }
  if (auto* u = vtkStringArray::SafeDownCast(f->GetAbstractArray("units"));
      u && u->GetNumberOfValues() == 3) {
    info.units.length = u->GetValue(0);
    info.units.time = u->GetValue(1);
    info.units.force = u->GetValue(2);
  }
  return info;
}

vtkSmartPointer<vtkPolyData> read_polydata(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw FormatError(file, "", "no such file");
  detail::ScopedVtkMessages messages;
  auto catcher = vtkSmartPointer<detail::VtkErrorCatcher>::New();
  vtkSmartPointer<vtkPolyData> out;
  if (file.extension() == ".pvtp") {
    auto reader = vtkSmartPointer<vtkXMLPPolyDataReader>::New();
    catcher->watch(reader);
    reader->SetFileName(file.c_str());
    reader->Update();
    out = reader->GetOutput();
  } else if (file.extension() == ".vtp") {
    auto reader = vtkSmartPointer<vtkXMLPolyDataReader>::New();
    catcher->watch(reader);
    if (reader->CanReadFile(file.c_str()) == 0) throw FormatError(file, "", "not a VTK XML PolyData file");
    reader->SetFileName(file.c_str());
    reader->Update();
    out = reader->GetOutput();
  } else {
    throw FormatError(file, "", "expected a .vtp or .pvtp file");
  }
  if (catcher->count > 0) throw FormatError(file, "", "VTK cannot read it: " + catcher->message);
  if (!messages.first().empty()) throw FormatError(file, "", "VTK cannot read it: " + messages.first());
  if (out == nullptr || out->GetPoints() == nullptr) throw FormatError(file, "", "no points in file");
  return out;
}

}  // namespace basalt::io
