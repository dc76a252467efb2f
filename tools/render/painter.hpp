#pragma once
// Drawing particles: spheres at their radii, coloured by a field through a cool-to-warm map with a
// colour bar, into an off-screen VTK window. basalt-view's render and movie commands and basalt-run's
// in-situ pictures (insitu_pictures.cpp, on the I/O ranks) draw through this.
#include <vtkActor.h>
#include <vtkMapper.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "basalt/io/vtk_frames.hpp"
#include "color_field.hpp"
#include "render_types.hpp"

class vtkTextProperty;

namespace basalt::view {

/// Whether broken bonds (cracks) are drawn: `automatic` when the frame has any (a checkpoint with broken
/// bonds), `on`, `off`, or `only` (the cracks without the particles).
enum class Cracks { automatic, on, off, only };

/// The fixed colour of the crack points (not on the cool-to-warm map, not the background): yellow.
inline constexpr double kCrackColour[3] = {1.0, 0.85, 0.0};

/// How particles are drawn (basalt-view render's options of the same names).
struct DrawOptions {
  std::string color;  ///< empty: speed when the frame has it, else radius
  std::optional<Cut> cut;
  ViewDirection view;
  std::string mapper = "imposter";  ///< "imposter" (GPU ray-cast spheres) or "glyph" (triangulated spheres)
  bool cull = true;                 ///< skip particles buried inside the packing (hidden behind others)
  Cracks cracks = Cracks::automatic;
  std::optional<double> crack_radius;  ///< radius of a crack point; default 0.3 x the mean particle radius
};

/// One frame ready to draw: the particles kept (cut, buried ones dropped), relative to the frame's
/// centre, with the colour values as active scalars and the radii as 32-bit floats for the imposters.
struct Prepared {
  std::filesystem::path input;  ///< the file it came from (its name is printed in a single picture)
  io::FrameInfo info;
  std::string kind;
  std::string field;
  vtkSmartPointer<vtkPolyData> shown;
  std::vector<double> drawn_values;  ///< the colour values of the particles the cut keeps
  std::array<double, 6> fit{};       ///< the whole frame's bounds (with radii) relative to its centre
  vtkIdType total = 0, in_view = 0;
  double read_s = 0;
  /// Broken bonds: one point each where it broke, those the cut keeps, relative to the frame's centre;
  /// null when cracks are not drawn.
  vtkSmartPointer<vtkPolyData> cracks;
  std::size_t cracks_total = 0;      ///< broken bonds in the frame
  std::size_t cracks_shown = 0;      ///< of them, in the half the cut keeps (all without a cut)
  std::size_t cracks_estimated = 0;  ///< of them, placed from the ends' current positions (no record)
  double crack_radius = 0;
  bool only_cracks = false;  ///< the particles are not drawn
};

/// Prepares `full` (particles as points with a "radius" array; its colour array is added to it) and the
/// broken bonds at `cracks` (drawn as o.cracks says, those on the kept side of the cut).
/// Throws io::FormatError (no particles, no radius) or std::invalid_argument (unknown field, empty cut),
/// naming `input`.
Prepared prepare(vtkSmartPointer<vtkPolyData> full, const io::FrameInfo& info, const std::string& kind,
                 const std::filesystem::path& input, const DrawOptions& o,
                 const std::vector<io::Vec3>& cracks = {});

/// The window, renderers, mappers and colour bar, set up once and reused for every picture: the
/// OpenGL set-up (shader compilation in software) costs about 2 s, the drawing itself far less.
class Painter {
 public:
  Painter(ImageSize size, int panels, DrawOptions o);
  /// Draws one frame per panel (as many as the painter has) with the colour map over `scale`.
  void draw(const std::vector<const Prepared*>& frames, const ColourScale& scale);
  vtkRenderWindow& window() { return *window_; }

 private:
  struct Panel {
    vtkSmartPointer<vtkRenderer> scene;
    vtkSmartPointer<vtkMapper> mapper;
    vtkSmartPointer<vtkActor> particles;
    vtkSmartPointer<vtkTextActor> text;
    // Cracks: a second layer over the particles, same viewport and camera.
    vtkSmartPointer<vtkRenderer> over;
    vtkSmartPointer<vtkMapper> crack_mapper;
    vtkSmartPointer<vtkSphereSource> crack_sphere;  ///< the glyph mapper's sphere
    vtkSmartPointer<vtkActor> cracks;
  };
  static void white(vtkTextProperty* t, int font);

  ImageSize size_;
  DrawOptions o_;
  int font_ = 10, bar_px_ = 100;
  vtkSmartPointer<vtkRenderWindow> window_;
  std::vector<Panel> panels_;
  vtkSmartPointer<vtkScalarBarActor> bar_;
  vtkSmartPointer<vtkTextActor> extremes_;
};

}  // namespace basalt::view
