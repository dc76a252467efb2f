#pragma once
#include <stdexcept>
#include <string>

namespace basalt::packer {

/// An impossible request (bad radii, a volume too small, an open mesh ...): what() says what and why.
class PackError : public std::runtime_error {
 public:
  explicit PackError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace basalt::packer
