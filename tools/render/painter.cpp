#include "painter.hpp"

#include <fmt/format.h>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkColorTransferFunction.h>
#include <vtkFloatArray.h>
#include <vtkGlyph3DMapper.h>
#include <vtkLookupTable.h>
#include <vtkOpenGLSphereMapper.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkSphereSource.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "basalt/io/geometry.hpp"
#include "particle_selection.hpp"

namespace basalt::view {

namespace fs = std::filesystem;

namespace {

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

const char* kColourArray = "basalt-view colour";

/// The broken bonds the cut keeps, as points (one vertex cell each) less `centre`.
vtkSmartPointer<vtkPolyData> crack_points(const std::vector<io::Vec3>& cracks,
                                          const std::optional<CutPlane>& cut, const double centre[3]) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  for (const auto& x : cracks) {
    if (cut && !cut->keeps(x[static_cast<std::size_t>(cut->axis)])) continue;
    const vtkIdType id = points->InsertNextPoint(x[0] - centre[0], x[1] - centre[1], x[2] - centre[2]);
    verts->InsertNextCell(1, &id);
  }
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->SetPoints(points);
  out->SetVerts(verts);
  return out;
}

/// "1234 broken bonds" and, with a cut, how many lie in the half drawn.
std::string crack_caption(const Prepared& p, bool cut) {
  if (!p.cracks) return {};
  return cut ? fmt::format("{} broken bonds, {} in the half drawn", p.cracks_total, p.cracks_shown)
             : fmt::format("{} broken bonds", p.cracks_total);
}

}  // namespace

Prepared prepare(vtkSmartPointer<vtkPolyData> polydata, const io::FrameInfo& info, const std::string& kind,
                 const fs::path& input, const DrawOptions& o, const std::vector<io::Vec3>& cracks) {
  Prepared p;
  p.input = input;
  p.info = info;
  p.kind = kind;
  vtkPolyData& full = *polydata;
  p.total = full.GetNumberOfPoints();
  if (p.total == 0) throw io::FormatError(input, "", "no particles to draw");
  if (full.GetPointData()->GetArray("radius") == nullptr)
    throw io::FormatError(input, "", "no \"radius\" point array: cannot size the spheres");

  p.field = o.color;
  if (p.field.empty()) p.field = full.GetPointData()->GetArray("speed") ? "speed" : "radius";
  auto values = color_values(full, p.field);
  values->SetName(kColourArray);
  full.GetPointData()->AddArray(values);
  double b[6];
  full.GetBounds(b);

  // Which particles to draw: the cut's half, less those buried inside the packing.
  std::vector<vtkIdType> kept;
  if (o.cut) {
    kept = cut_indices(full, *o.cut, o.view);
  } else {
    kept.resize(static_cast<std::size_t>(p.total));
    for (vtkIdType i = 0; i < p.total; ++i) kept[static_cast<std::size_t>(i)] = i;
  }
  p.in_view = static_cast<vtkIdType>(kept.size());
  if (p.in_view == 0) {
    const int a = o.cut->axis;
    throw std::invalid_argument(
        fmt::format("{}: --cut: no particles left (the particles' {} runs from {} to {})", input.string(),
                    static_cast<char>('x' + a), b[2 * a], b[2 * a + 1]));
  }
  // The colour range is taken from every particle the cut keeps, buried ones included, so that
  // skipping them (a matter of speed) never changes a colour.
  p.drawn_values.reserve(kept.size());
  for (vtkIdType i : kept) p.drawn_values.push_back(values->GetValue(i));
  double rr[2];
  full.GetPointData()->GetArray("radius")->GetRange(rr);
  if (o.cull) kept = drop_buried(full, kept, 2 * rr[1]);
  vtkSmartPointer<vtkPolyData> shown =
      static_cast<vtkIdType>(kept.size()) == p.total ? polydata : select_points(full, kept);
  // Drawn relative to the frame's centre: OpenGL works in single precision, so particles 1e9 from the
  // origin (1e12: nothing at all) collapsed onto a few positions and the picture was blank.
  const double centre[3] = {0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5])};
  p.shown = relative_to(*shown, centre);
  p.shown->GetPointData()->SetActiveScalars(kColourArray);

  // VTK 9.1's sphere mapper reads its scale array as 32-bit floats: give it a float copy.
  vtkDataArray* radius = p.shown->GetPointData()->GetArray("radius");
  auto radius32 = vtkSmartPointer<vtkFloatArray>::New();
  radius32->SetName("radius_float32");
  radius32->SetNumberOfTuples(radius->GetNumberOfTuples());
  for (vtkIdType i = 0; i < radius->GetNumberOfTuples(); ++i)
    radius32->SetValue(i, static_cast<float>(radius->GetComponent(i, 0)));
  p.shown->GetPointData()->AddArray(radius32);

  // The camera fits the whole frame (not just the kept half), including the spheres' radii.
  const double pad = rr[1];
  p.fit = {b[0] - centre[0] - pad, b[1] - centre[0] + pad, b[2] - centre[1] - pad,
           b[3] - centre[1] + pad, b[4] - centre[2] - pad, b[5] - centre[2] + pad};

  // Broken bonds: drawn when asked, or by default when there are any.
  const bool with_cracks = o.cracks == Cracks::on || o.cracks == Cracks::only ||
                           (o.cracks == Cracks::automatic && !cracks.empty());
  if (with_cracks) {
    std::optional<CutPlane> plane;
    if (o.cut) plane = cut_plane(full, *o.cut, o.view);
    p.cracks = crack_points(cracks, plane, centre);
    p.cracks_total = cracks.size();
    p.cracks_shown = static_cast<std::size_t>(p.cracks->GetNumberOfPoints());
    double mean = 0;
    for (vtkIdType i = 0; i < radius->GetNumberOfTuples(); ++i) mean += radius->GetComponent(i, 0);
    p.crack_radius = o.crack_radius.value_or(0.3 * mean / static_cast<double>(radius->GetNumberOfTuples()));
    p.only_cracks = o.cracks == Cracks::only;
  }
  return p;
}

Painter::Painter(ImageSize size, int panels, DrawOptions o) : size_(size), o_(std::move(o)) {
  const double bg[3] = {0.32, 0.34, 0.43};
  // The colour bar's panel: 16 % of a single picture's width, of a 1.6:1 picture's for a strip.
  const double bar_px = 0.16 * std::min(static_cast<double>(size.width), 1.6 * size.height);
  const double bar = std::min(0.5, bar_px / size.width);
  bar_px_ = static_cast<int>(bar * size.width);
  window_ = vtkSmartPointer<vtkRenderWindow>::New();
  window_->SetOffScreenRendering(1);
  window_->SetMultiSamples(0);
  window_->SetSize(size.width, size.height);
  window_->SetNumberOfLayers(2);  // layer 1: the cracks, over the particles
  font_ = std::max(10, size.height / 48);
  for (int i = 0; i < panels; ++i) {
    Panel pn;
    pn.scene = vtkSmartPointer<vtkRenderer>::New();
    const double w = (1 - bar) / panels;
    pn.scene->SetViewport(i * w, 0, (i + 1) * w, 1);
    pn.scene->SetBackground(bg[0], bg[1], bg[2]);
    if (o_.mapper == "imposter") {
      auto spheres = vtkSmartPointer<vtkOpenGLSphereMapper>::New();
      spheres->SetScaleArray("radius_float32");
      pn.mapper = spheres;
    } else {
      auto sphere = vtkSmartPointer<vtkSphereSource>::New();
      sphere->SetRadius(1.0);
      sphere->SetThetaResolution(10);
      sphere->SetPhiResolution(6);
      auto glyphs = vtkSmartPointer<vtkGlyph3DMapper>::New();
      glyphs->SetSourceConnection(sphere->GetOutputPort());
      glyphs->SetScaleArray("radius");
      glyphs->SetScaleModeToScaleByMagnitude();
      glyphs->SetScaleFactor(1.0);
      glyphs->OrientOff();
      pn.mapper = glyphs;
    }
    pn.mapper->SetScalarModeToUsePointData();
    pn.mapper->ScalarVisibilityOn();
    pn.mapper->UseLookupTableScalarRangeOn();
    pn.particles = vtkSmartPointer<vtkActor>::New();
    pn.particles->SetMapper(pn.mapper);
    pn.particles->GetProperty()->SetAmbient(0.15);
    pn.particles->GetProperty()->SetDiffuse(0.85);
    pn.particles->GetProperty()->SetSpecular(0.0);
    pn.scene->AddActor(pn.particles);
    // Cracks on a layer of their own, drawn after the particles with a cleared depth buffer, so that every
    // broken bond in the half drawn shows (over the particles, not hidden inside the packing).
    pn.over = vtkSmartPointer<vtkRenderer>::New();
    pn.over->SetLayer(1);
    pn.over->SetViewport(i * w, 0, (i + 1) * w, 1);
    pn.over->SetActiveCamera(pn.scene->GetActiveCamera());
    pn.over->InteractiveOff();
    if (o_.mapper == "imposter") {
      pn.crack_mapper = vtkSmartPointer<vtkOpenGLSphereMapper>::New();
    } else {
      pn.crack_sphere = vtkSmartPointer<vtkSphereSource>::New();
      pn.crack_sphere->SetThetaResolution(10);
      pn.crack_sphere->SetPhiResolution(6);
      auto glyphs = vtkSmartPointer<vtkGlyph3DMapper>::New();
      glyphs->SetSourceConnection(pn.crack_sphere->GetOutputPort());
      glyphs->ScalingOff();
      glyphs->OrientOff();
      pn.crack_mapper = glyphs;
    }
    pn.crack_mapper->ScalarVisibilityOff();
    pn.cracks = vtkSmartPointer<vtkActor>::New();
    pn.cracks->SetMapper(pn.crack_mapper);
    pn.cracks->GetProperty()->SetColor(kCrackColour[0], kCrackColour[1], kCrackColour[2]);
    pn.cracks->GetProperty()->SetAmbient(0.4);
    pn.cracks->GetProperty()->SetDiffuse(0.6);
    pn.cracks->GetProperty()->SetSpecular(0.0);
    pn.cracks->VisibilityOff();
    pn.over->AddActor(pn.cracks);
    pn.text = vtkSmartPointer<vtkTextActor>::New();
    white(pn.text->GetTextProperty(), font_);
    pn.text->GetTextProperty()->SetVerticalJustificationToTop();
    // Display coordinates are the window's, not the panel's.
    pn.text->SetDisplayPosition(static_cast<int>(i * w * size.width) + font_ / 2, size.height - font_ / 2);
    pn.scene->AddActor2D(pn.text);
    window_->AddRenderer(pn.scene);
    window_->AddRenderer(pn.over);
    panels_.push_back(pn);
  }
  auto side = vtkSmartPointer<vtkRenderer>::New();
  side->SetViewport(1 - bar, 0, 1, 1);
  side->SetBackground(bg[0], bg[1], bg[2]);
  side->InteractiveOff();
  bar_ = vtkSmartPointer<vtkScalarBarActor>::New();
  bar_->SetNumberOfLabels(6);
  bar_->SetLabelFormat("%-#8.4g");
  bar_->UnconstrainedFontSizeOn();
  bar_->SetPosition(0.12, 0.1);
  bar_->SetPosition2(0.8, 0.84);
  bar_->SetBarRatio(0.3);
  bar_->SetVerticalTitleSeparation(font_);
  bar_->SetTextPad(font_ / 3);
  white(bar_->GetLabelTextProperty(), font_ * 5 / 6);
  side->AddActor2D(bar_);
  extremes_ = vtkSmartPointer<vtkTextActor>::New();
  white(extremes_->GetTextProperty(), font_ * 5 / 6);
  extremes_->SetDisplayPosition(static_cast<int>((1 - bar) * size.width) + font_ / 2, font_ / 2);
  side->AddActor2D(extremes_);
  window_->AddRenderer(side);
}

void Painter::draw(const std::vector<const Prepared*>& frames, const ColourScale& scale) {
  auto lut = cool_to_warm(scale.range);
  const std::string& field = frames.front()->field;
  const std::string title = fmt::format("{}\n{}", field_title(field, frames.front()->info.units), scale.how);
  bar_->SetLookupTable(lut);
  bar_->SetTitle(title.c_str());
  // The title must fit the colour bar's panel: about 0.6 font sizes per character of its longest line.
  const auto longest = static_cast<double>(std::max(title.find('\n'), title.size() - title.find('\n') - 1));
  white(bar_->GetTitleTextProperty(),
        std::max(7, std::min(font_, static_cast<int>(0.9 * bar_px_ / (0.6 * longest)))));
  extremes_->SetInput(fmt::format("min {:.4g}\nmax {:.4g}", scale.min, scale.max).c_str());
  // Only cracks in every panel: no particles, so no colour bar either.
  const bool bar =
      std::any_of(frames.begin(), frames.end(), [](const Prepared* p) { return !p->only_cracks; });
  bar_->SetVisibility(bar);
  extremes_->SetVisibility(bar);
  for (std::size_t i = 0; i < panels_.size(); ++i) {
    const Prepared& p = *frames[i];
    Panel& pn = panels_[i];
    pn.mapper->SetLookupTable(lut);
    if (auto* m = vtkPolyDataMapper::SafeDownCast(pn.mapper)) m->SetInputData(p.shown);
    if (auto* g = vtkGlyph3DMapper::SafeDownCast(pn.mapper)) g->SetInputData(p.shown);
    pn.particles->SetVisibility(!p.only_cracks);
    pn.cracks->SetVisibility(p.cracks && p.cracks_shown > 0);
    if (p.cracks) {
      if (auto* m = vtkOpenGLSphereMapper::SafeDownCast(pn.crack_mapper)) {
        m->SetInputData(p.cracks);
        m->SetRadius(static_cast<float>(p.crack_radius));
      }
      if (auto* g = vtkGlyph3DMapper::SafeDownCast(pn.crack_mapper)) {
        g->SetInputData(p.cracks);
        pn.crack_sphere->SetRadius(p.crack_radius);
      }
    }
    const std::string cut = o_.cut ? fmt::format(" ({} behind the cut at {})", p.in_view,
                                                 std::string(1, static_cast<char>('x' + o_.cut->axis)))
                                   : std::string();
    const std::string cracks =
        p.cracks ? fmt::format("\n{}", crack_caption(p, o_.cut.has_value())) : std::string();
    // A strip's panels say only their clock (and broken bonds): the file names are in the command.
    pn.text->SetInput(panels_.size() > 1
                          ? fmt::format("{}{}", describe_clock(p.info, p.kind), cracks).c_str()
                          : fmt::format("{}\n{}: {} particles{}{}", describe_clock(p.info, p.kind),
                                        p.input.filename().string(), p.total, cut, cracks)
                                .c_str());
    // Camera: look at the centre of the whole frame (now the origin) from the requested side.
    auto* cam = pn.scene->GetActiveCamera();
    cam->SetFocalPoint(0, 0, 0);
    cam->SetPosition(o_.view.toward_camera.data());
    cam->SetViewUp(o_.view.up.data());
    cam->SetViewAngle(30);
    double fit[6];
    std::copy(p.fit.begin(), p.fit.end(), fit);
    pn.scene->ResetCamera(fit);
    // A strip's narrow panels: fill them when looking along an axis (a cube shows as a square, narrower
    // than its bounding sphere, which ResetCamera fits); the iso view's hexagon needs the margin.
    const auto& t = o_.view.toward_camera;
    const bool along_axis = (t[0] != 0) + (t[1] != 0) + (t[2] != 0) == 1;
    cam->Zoom(panels_.size() == 1 ? 1.25 : along_axis ? 1.6 : 1.1);
    pn.scene->ResetCameraClippingRange(fit);
  }
  window_->Render();
}

void Painter::white(vtkTextProperty* t, int font) {
  t->SetFontSize(font);
  t->SetColor(1, 1, 1);
  t->ItalicOff();
  t->ShadowOff();
}

}  // namespace basalt::view
