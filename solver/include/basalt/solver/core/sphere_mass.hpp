#pragma once
// The mass of a sphere of uniform density: one expression for every place that gives a particle its mass
// (a geometry without masses, inserted particles, the stability estimate's lightest particle), so that they
// agree to the bit.
#include <cmath>
#include <numbers>

namespace basalt::solver {

inline double sphere_mass(double density, double radius) {
  return density * 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
}

}  // namespace basalt::solver
