#pragma once
// The two kinds of failure a run reports: bad input (before anything starts) and a run that went wrong.
#include <stdexcept>
#include <string>

namespace basalt::solver {

/// Bad scene or command-line input. what() names the file, line and key.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run that cannot go on (instability, lost particle, bond longer than the ghost width ...).
/// what() names the step, the particle id(s) and the numbers.
class RunError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace basalt::solver
