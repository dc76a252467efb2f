#include "units.hpp"

#include <fmt/format.h>

namespace basalt::view {

namespace {
bool contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }
}  // namespace

std::string velocity_units(const io::Units& u) { return u.length + "/" + u.time; }

std::string energy_units(const io::Units& u) {
  const std::string e = u.force + "\u00b7" + u.length;  // N·mm
  if (u.force == "N" && u.length == "mm") return e + " = mJ";
  if (u.force == "N" && u.length == "m") return e + " = J";
  return e;
}

std::string mass_units(const io::Units& u) {
  if (!u.mass.empty()) return u.mass;
  // F = m a: mass = force · time² / length. N·ms²/mm = 1e-3 kg = g.
  if (u.force == "N" && u.time == "ms" && u.length == "mm") return "g";
  if (u.force == "N" && u.time == "s" && u.length == "m") return "kg";
  return fmt::format("{}\u00b7{}\u00b2/{}", u.force, u.time, u.length);
}

std::string quantity_units(const std::string& name, const io::Units& u) {
  if (name == "id" || name == "tag" || contains(name, "count") || contains(name, "number")) return "";
  if (contains(name, "energy") || contains(name, "work")) return energy_units(u);
  if (contains(name, "force")) return u.force;
  if (contains(name, "momentum")) return mass_units(u) + "\u00b7" + velocity_units(u);
  if (contains(name, "angular_velocity") || contains(name, "angular_speed")) return "rad/" + u.time;
  if (contains(name, "velocity") || contains(name, "speed")) return velocity_units(u);
  if (name == "mass" || contains(name, "_mass")) return mass_units(u);
  if (name == "radius" || contains(name, "displacement") || contains(name, "position") || name == "x" ||
      name == "y" || name == "z")
    return u.length;
  if (name == "time") return u.time;
  return "";
}

}  // namespace basalt::view
