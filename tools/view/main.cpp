// basalt-view: render checkpoints and geometries to PNG, convert them to VTK, plot field series.
#include <fmt/format.h>
#include <vtkPointData.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "basalt/version.hpp"
#include "color_field.hpp"
#include "convert_command.hpp"
#include "display.hpp"
#include "options.hpp"
#include "particle_frame.hpp"
#include "plot_command.hpp"
#include "render_command.hpp"

namespace bv = basalt::view;

int main(int argc, char** argv) {
  CLI::App app{
      "basalt-view: render Basalt checkpoints and geometries to PNG, convert them to VTK for ParaView, "
      "plot field series.\nRendering needs X: without DISPLAY, basalt-view starts its own Xvfb."};
  app.set_version_flag("--version", std::string(basalt::kVersion));
  app.require_subcommand(1);

  bv::RenderOptions r;
  std::string size, view = "iso", cut, range, color;
  std::string reference;
  auto* render =
      app.add_subcommand("render", "Draw the particles as spheres coloured by a field, write a PNG");
  render
      ->add_option("files", r.inputs,
                   "checkpoints (.h5), geometries (.h5/.geo) or VTK frames (.vtp/.pvtp); several: one "
                   "colour range for all")
      ->required();
  render
      ->add_option("-o,--output", r.output,
                   "PNG to write (several files: one panel each, side by side), or a folder (ending in '/'): "
                   "one PNG per file")
      ->required();
  render->add_option("--color", color,
                     "field: speed, displacement, tag, id, radius, mass, velocity_z, any stored array "
                     "(default: speed if present, else radius)");
  render->add_option("--size", size, "image WIDTHxHEIGHT (default 1600x1200; a strip: 560x600 per panel)");
  render->add_option("--view", view, "camera side: +x -x +y -y +z -z iso")->capture_default_str();
  render->add_option("--cut", cut,
                     "x|y|z[:VALUE]: drop the particles on the camera's side of this plane "
                     "(default VALUE: the middle)");
  render->add_option("--range", range,
                     "MIN:MAX of the colour map (default: 1st-99th percentile of the particles in view, "
                     "outside clamped)");
  render->add_option("--reference", reference, "initial geometry/checkpoint, for --color displacement");
  render
      ->add_option("--mapper", r.mapper, "imposter (ray-cast spheres, fast) or glyph (triangulated spheres)")
      ->capture_default_str();
  bool draw_all = false;
  render->add_flag(
      "--all", draw_all,
      "draw every particle, also those buried inside the packing (slower; same picture up to a few "
      "pixels)");
  bool cracks = false, no_cracks = false, only_cracks = false;
  auto* cracks_flag = render->add_flag(
      "--cracks", cracks,
      "draw broken bonds, one yellow point each where it broke, over the particles (default when a "
      "checkpoint has broken bonds)");
  auto* no_cracks_flag = render->add_flag("--no-cracks", no_cracks, "do not draw broken bonds");
  auto* only_cracks_flag =
      render->add_flag("--only-cracks", only_cracks, "draw the broken bonds alone, without the particles");
  cracks_flag->excludes(no_cracks_flag)->excludes(only_cracks_flag);
  no_cracks_flag->excludes(only_cracks_flag);
  double crack_radius = 0;
  auto* crack_radius_opt =
      render->add_option("--crack-radius", crack_radius,
                         "radius of a broken bond's point (default: 0.3 x the mean particle radius)");
  render->add_flag("-q,--quiet", r.quiet, "print nothing on success");

  bv::MovieOptions m;
  std::string movie_size = "800x600", movie_view = "iso", movie_cut, movie_range, movie_reference;
  auto* movie = app.add_subcommand(
      "movie", "Render checkpoints (a run's folder, or files) with one colour range into an animated PNG");
  movie
      ->add_option("files", m.render.inputs,
                   "a run's output folder (its ckpt_<step>.h5 in step order), or files")
      ->required();
  movie->add_option("-o,--output", m.render.output, "animated PNG to write (.png or .apng)")->required();
  movie->add_option("--color", m.render.color, "field, as for render");
  movie->add_option("--size", movie_size, "image WIDTHxHEIGHT")->capture_default_str();
  movie->add_option("--view", movie_view, "camera side: +x -x +y -y +z -z iso")->capture_default_str();
  movie->add_option("--cut", movie_cut, "x|y|z[:VALUE], as for render");
  movie->add_option("--range", movie_range, "MIN:MAX (default: 1st-99th percentile over every frame)");
  movie->add_option("--reference", movie_reference, "initial geometry/checkpoint, for --color displacement");
  movie->add_option("--fps", m.fps, "frames per second")->capture_default_str();
  movie->add_flag("-q,--quiet", m.render.quiet, "print nothing but errors");

  bv::ConvertOptions c;
  std::string convert_reference;
  auto* convert = app.add_subcommand(
      "convert",
      "Write VTK XML for ParaView (one input to .vtp, many to a .pvd series), or a geometry to "
      "another geometry format (.geo to .h5 for basalt-run, .h5 to .geo for ESyS-Particle)");
  convert->add_option("files", c.inputs, "checkpoints (.h5) or geometries (.h5/.geo)")->required();
  convert
      ->add_option("-o,--output", c.output,
                   "frame.vtp (one input), series.pvd (any number), or a geometry .h5/.geo (one geometry)")
      ->required();
  convert->add_option("--reference", convert_reference,
                      "initial geometry/checkpoint: adds a displacement array");
  convert->add_flag("-q,--quiet", c.quiet, "print nothing on success");

  bv::PlotOptions p;
  std::string plot_size = "1200x800", columns, units_from;
  auto* plot = app.add_subcommand("plot", "Plot field-saver series (fields.csv) against time, write a PNG");
  plot->add_option("file", p.input, "CSV: step,time,<field>... then numeric rows")->required();
  plot->add_option("-o,--output", p.output, "PNG to write")->required();
  plot->add_option("--columns", columns, "comma-separated columns (default: all after step,time)");
  plot->add_option("--units-from", units_from,
                   "scene TOML whose [units] gives length/time/force (default mm, ms, N)");
  plot->add_option("--ylabel", p.ylabel,
                   "label of the vertical axis (default: from the column and its units)");
  plot->add_option("--title", p.title, "title above the chart");
  plot->add_option("--size", plot_size, "image WIDTHxHEIGHT")->capture_default_str();
  plot->add_flag("-q,--quiet", p.quiet, "print nothing on success");

  auto* info =
      app.add_subcommand("info", "Print a file's particle count, clock and the fields it can be coloured by");
  std::string info_file;
  info->add_option("file", info_file, "checkpoint, geometry or VTK frame")->required();

  CLI11_PARSE(app, argc, argv);

  try {
    if (render->parsed()) {
      if (!size.empty()) r.size = bv::parse_size(size);
      r.view = bv::parse_view(view);
      if (!cut.empty()) r.cut = bv::parse_cut(cut);
      if (!range.empty()) r.range = bv::parse_range(range);
      if (!reference.empty()) r.reference = reference;
      r.color = color;
      r.cull = !draw_all;
      r.cracks = cracks        ? bv::Cracks::on
                 : no_cracks   ? bv::Cracks::off
                 : only_cracks ? bv::Cracks::only
                               : bv::Cracks::automatic;
      if (crack_radius_opt->count() > 0) r.crack_radius = crack_radius;
      bv::ensure_display();
      bv::render(r);
    } else if (movie->parsed()) {
      m.render.size = bv::parse_size(movie_size);
      m.render.view = bv::parse_view(movie_view);
      if (!movie_cut.empty()) m.render.cut = bv::parse_cut(movie_cut);
      if (!movie_range.empty()) m.render.range = bv::parse_range(movie_range);
      if (!movie_reference.empty()) m.render.reference = movie_reference;
      bv::ensure_display();
      bv::movie(m);
    } else if (convert->parsed()) {
      if (!convert_reference.empty()) c.reference = convert_reference;
      bv::convert(c);
    } else if (plot->parsed()) {
      p.size = bv::parse_size(plot_size);
      if (!columns.empty()) {
        std::string rest = columns;
        for (std::size_t comma; (comma = rest.find(',')) != std::string::npos; rest.erase(0, comma + 1))
          p.columns.push_back(rest.substr(0, comma));
        p.columns.push_back(rest);
      }
      if (!units_from.empty()) p.units_from = units_from;
      bv::ensure_display();
      bv::plot(p);
    } else if (info->parsed()) {
      const bv::Frame f = bv::read_frame(info_file, std::nullopt);
      fmt::print("{}: {}, {} particles\n", info_file, f.kind, f.polydata->GetNumberOfPoints());
      if (f.info.has_clock) fmt::print("step {}, time {} {}\n", f.info.step, f.info.time, f.info.units.time);
      fmt::print("units: length {}, time {}, force {}\n", f.info.units.length, f.info.units.time,
                 f.info.units.force);
      fmt::print("colour fields: {}\n", fmt::join(bv::color_fields(*f.polydata), ", "));
    }
  } catch (const std::exception& e) {
    std::fflush(stdout);
    fmt::print(stderr, "basalt-view: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
