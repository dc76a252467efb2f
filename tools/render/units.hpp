#pragma once
// Units of the quantities Basalt writes, derived from a run's length/time/force units
// (default mm, ms, N: velocity mm/ms, energy N·mm = mJ, mass g).
#include <string>

#include "basalt/io/geometry.hpp"

namespace basalt::view {

std::string velocity_units(const io::Units& u);
std::string energy_units(const io::Units& u);
std::string mass_units(const io::Units& u);

/// Units of a named quantity (a particle array such as "radius" or "speed", or a field-saver column
/// such as "kinetic_energy" or "wall_force"): "" when unknown or dimensionless (id, tag, counts).
std::string quantity_units(const std::string& name, const io::Units& u);

}  // namespace basalt::view
