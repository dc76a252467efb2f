#include "render_command.hpp"

#include <fmt/format.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkFloatArray.h>
#include <vtkGlyph3DMapper.h>
#include <vtkLookupTable.h>
#include <vtkOpenGLSphereMapper.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "color_field.hpp"
#include "particle_frame.hpp"
#include "particle_selection.hpp"
#include "png_output.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// ParaView's "Cool to Warm": blue for low, red for high, perceptually even, readable on grey.
vtkSmartPointer<vtkLookupTable> cool_to_warm(const Range& r) {
  auto ctf = vtkSmartPointer<vtkColorTransferFunction>::New();
  ctf->SetColorSpaceToDiverging();
  ctf->AddRGBPoint(0.0, 0.230, 0.299, 0.754);
  ctf->AddRGBPoint(1.0, 0.706, 0.016, 0.150);
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  const int n = 256;
  lut->SetNumberOfTableValues(n);
  for (int i = 0; i < n; ++i) {
    double rgb[3];
    ctf->GetColor(static_cast<double>(i) / (n - 1), rgb);
    lut->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  lut->SetRange(r.min, r.max);
  lut->SetNanColor(0.5, 0.5, 0.5, 1.0);
  lut->Build();
  // Build() may recompute the table from its own ramp: set the values again afterwards.
  for (int i = 0; i < n; ++i) {
    double rgb[3];
    ctf->GetColor(static_cast<double>(i) / (n - 1), rgb);
    lut->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  return lut;
}

/// The same particles and arrays, positions less `centre` (in double precision).
vtkSmartPointer<vtkPolyData> relative_to(vtkPolyData& in, const double centre[3]) {
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(&in);
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  const vtkIdType n = in.GetNumberOfPoints();
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    in.GetPoint(i, p);
    points->SetPoint(i, p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]);
  }
  out->SetPoints(points);
  return out;
}

std::string describe_clock(const io::FrameInfo& info, const std::string& kind) {
  if (!info.has_clock) return fmt::format("{} (no step or time)", kind);
  return fmt::format("step {}   t = {:.6g} {}", info.step, info.time, info.units.time);
}

}  // namespace

void render(const RenderOptions& o) {
  require_writable(o.output.string());
  if (o.output.extension() != ".png")
    throw std::invalid_argument(fmt::format("output {}: render writes PNG images (.png)", o.output.string()));
  if (o.mapper != "imposter" && o.mapper != "glyph")
    throw std::invalid_argument(fmt::format("--mapper \"{}\": expected imposter or glyph", o.mapper));
  auto t0 = Clock::now();
  Frame frame = read_frame(o.input, o.reference);
  vtkPolyData& full = *frame.polydata;
  const vtkIdType total = full.GetNumberOfPoints();
  if (total == 0) throw io::FormatError(o.input, "", "no particles to draw");
  if (full.GetPointData()->GetArray("radius") == nullptr)
    throw io::FormatError(o.input, "", "no \"radius\" point array: cannot size the spheres");

  std::string field = o.color;
  if (field.empty()) field = full.GetPointData()->GetArray("speed") ? "speed" : "radius";
  // Colour values are taken before the cut so that the range describes the whole frame.
  const std::string color_array = "basalt-view colour: " + field;
  auto values = color_values(full, field);
  values->SetName(color_array.c_str());
  full.GetPointData()->AddArray(values);
  full.GetPointData()->SetActiveScalars(color_array.c_str());
  double full_bounds[6];
  full.GetBounds(full_bounds);

  // Which particles to draw: the cut's half, less those buried inside the packing.
  std::vector<vtkIdType> kept;
  if (o.cut) {
    kept = cut_indices(full, *o.cut, o.view);
  } else {
    kept.resize(static_cast<std::size_t>(total));
    for (vtkIdType i = 0; i < total; ++i) kept[static_cast<std::size_t>(i)] = i;
  }
  const auto in_view = static_cast<vtkIdType>(kept.size());
  if (in_view == 0) {
    const int a = o.cut->axis;
    throw std::invalid_argument(fmt::format("--cut: no particles left (the particles' {} runs from {} to {})",
                                            static_cast<char>('x' + a), full_bounds[2 * a],
                                            full_bounds[2 * a + 1]));
  }
  if (o.cull) {
    double rr[2];
    full.GetPointData()->GetArray("radius")->GetRange(rr);
    kept = drop_buried(full, kept, 2 * rr[1]);
  }
  vtkSmartPointer<vtkPolyData> shown =
      static_cast<vtkIdType>(kept.size()) == total ? frame.polydata : select_points(full, kept);
  shown->GetPointData()->SetActiveScalars(color_array.c_str());
  // Drawn relative to the frame's centre: OpenGL works in single precision, so particles 1e9 from the
  // origin (1e12: nothing at all) collapsed onto a few positions and the picture was blank.
  const double centre[3] = {0.5 * (full_bounds[0] + full_bounds[1]), 0.5 * (full_bounds[2] + full_bounds[3]),
                            0.5 * (full_bounds[4] + full_bounds[5])};
  shown = relative_to(*shown, centre);
  const double read_s = seconds_since(t0);

  Range range;
  if (o.range) {
    range = *o.range;
  } else {
    double r[2];
    values->GetRange(r);
    range = {r[0], r[1]};
    if (!(range.min < range.max)) {  // a constant field: centre it in the map
      const double pad = range.min == 0 ? 1.0 : 0.05 * std::abs(range.min);
      range = {range.min - pad, range.max + pad};
    }
  }
  auto lut = cool_to_warm(range);

  vtkSmartPointer<vtkPolyDataMapper> mapper;
  if (o.mapper == "imposter") {
    // VTK 9.1's sphere mapper reads its scale array as 32-bit floats: give it a float copy.
    vtkDataArray* radius = shown->GetPointData()->GetArray("radius");
    auto radius32 = vtkSmartPointer<vtkFloatArray>::New();
    radius32->SetName("radius_float32");
    radius32->SetNumberOfTuples(radius->GetNumberOfTuples());
    for (vtkIdType i = 0; i < radius->GetNumberOfTuples(); ++i)
      radius32->SetValue(i, static_cast<float>(radius->GetComponent(i, 0)));
    shown->GetPointData()->AddArray(radius32);
    auto spheres = vtkSmartPointer<vtkOpenGLSphereMapper>::New();
    spheres->SetScaleArray("radius_float32");
    mapper = spheres;
  }
  vtkSmartPointer<vtkMapper> any_mapper;
  if (mapper) {
    mapper->SetInputData(shown);
    any_mapper = mapper;
  } else {
    auto sphere = vtkSmartPointer<vtkSphereSource>::New();
    sphere->SetRadius(1.0);
    sphere->SetThetaResolution(10);
    sphere->SetPhiResolution(6);
    auto glyphs = vtkSmartPointer<vtkGlyph3DMapper>::New();
    glyphs->SetInputData(shown);
    glyphs->SetSourceConnection(sphere->GetOutputPort());
    glyphs->SetScaleArray("radius");
    glyphs->SetScaleModeToScaleByMagnitude();
    glyphs->SetScaleFactor(1.0);
    glyphs->OrientOff();
    any_mapper = glyphs;
  }
  any_mapper->SetLookupTable(lut);
  any_mapper->SetScalarModeToUsePointData();
  any_mapper->ScalarVisibilityOn();
  any_mapper->UseLookupTableScalarRangeOn();

  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(any_mapper);
  actor->GetProperty()->SetAmbient(0.15);
  actor->GetProperty()->SetDiffuse(0.85);
  actor->GetProperty()->SetSpecular(0.0);

  const double bg[3] = {0.32, 0.34, 0.43};
  const double bar_width = 0.16;  // fraction of the image on the right for the colour bar
  auto scene = vtkSmartPointer<vtkRenderer>::New();
  scene->SetViewport(0, 0, 1 - bar_width, 1);
  scene->SetBackground(bg[0], bg[1], bg[2]);
  scene->AddActor(actor);
  auto side = vtkSmartPointer<vtkRenderer>::New();
  side->SetViewport(1 - bar_width, 0, 1, 1);
  side->SetBackground(bg[0], bg[1], bg[2]);
  side->InteractiveOff();

  const int h = o.size.height;
  const int font = std::max(10, h / 48);
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(lut);
  const std::string title = field_title(field, frame.info.units);
  bar->SetTitle(title.c_str());
  // The title must fit the colour bar's panel: about 0.6 font sizes per character.
  const int panel_px = static_cast<int>(bar_width * o.size.width);
  const int title_font = std::max(
      7, std::min(font, static_cast<int>(0.9 * panel_px / (0.6 * static_cast<double>(title.size())))));
  bar->SetNumberOfLabels(6);
  bar->SetLabelFormat("%-#8.4g");
  bar->UnconstrainedFontSizeOn();
  bar->SetPosition(0.12, 0.08);
  bar->SetPosition2(0.8, 0.86);
  bar->SetBarRatio(0.3);
  bar->SetVerticalTitleSeparation(font);
  bar->SetTextPad(font / 3);
  bar->GetTitleTextProperty()->SetFontSize(title_font);
  bar->GetTitleTextProperty()->SetColor(1, 1, 1);
  bar->GetTitleTextProperty()->ItalicOff();
  bar->GetTitleTextProperty()->ShadowOff();
  bar->GetLabelTextProperty()->SetFontSize(font * 5 / 6);
  bar->GetLabelTextProperty()->SetColor(1, 1, 1);
  bar->GetLabelTextProperty()->ItalicOff();
  bar->GetLabelTextProperty()->ShadowOff();
  side->AddActor2D(bar);

  auto text = vtkSmartPointer<vtkTextActor>::New();
  text->SetInput(fmt::format("{}\n{}: {} particles{}", describe_clock(frame.info, frame.kind),
                             o.input.filename().string(), total,
                             o.cut ? fmt::format(" ({} behind the cut at {})", in_view,
                                                 std::string(1, static_cast<char>('x' + o.cut->axis)))
                                   : std::string())
                     .c_str());
  text->GetTextProperty()->SetFontSize(font);
  text->GetTextProperty()->SetColor(1, 1, 1);
  text->GetTextProperty()->SetVerticalJustificationToTop();
  text->SetDisplayPosition(font / 2, h - font / 2);
  scene->AddActor2D(text);

  // Camera: look at the centre of the whole frame (now the origin) from the requested side.
  auto* cam = scene->GetActiveCamera();
  const double c[3] = {0, 0, 0};
  cam->SetFocalPoint(c);
  cam->SetPosition(c[0] + o.view.toward_camera[0], c[1] + o.view.toward_camera[1],
                   c[2] + o.view.toward_camera[2]);
  cam->SetViewUp(o.view.up.data());
  cam->SetViewAngle(30);
  // Fit the whole frame (not just the kept half), including the spheres' radii.
  double rr[2];
  full.GetPointData()->GetArray("radius")->GetRange(rr);
  const double pad = rr[1];
  const double fit[6] = {full_bounds[0] - centre[0] - pad, full_bounds[1] - centre[0] + pad,
                         full_bounds[2] - centre[1] - pad, full_bounds[3] - centre[1] + pad,
                         full_bounds[4] - centre[2] - pad, full_bounds[5] - centre[2] + pad};
  scene->ResetCamera(fit);
  cam->Zoom(1.25);
  scene->ResetCameraClippingRange(fit);

  auto window = vtkSmartPointer<vtkRenderWindow>::New();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(o.size.width, o.size.height);
  window->AddRenderer(scene);
  window->AddRenderer(side);
  auto t1 = Clock::now();
  window->Render();
  write_png(*window, o.output);
  const double draw_s = seconds_since(t1);
  if (!o.quiet)
    fmt::print(
        "wrote {} ({}x{}, {} particles, {} in view, {} drawn, coloured by {}, range {:.6g}..{:.6g}; read "
        "{:.2f} s, "
        "draw {:.2f} s)\n",
        o.output.string(), o.size.width, o.size.height, total, in_view, shown->GetNumberOfPoints(), field,
        range.min, range.max, read_s, draw_s);
}

}  // namespace basalt::view
