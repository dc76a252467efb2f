// libFuzzer target: the scene parser (solver/src/scene.cpp) on arbitrary text. A scene either parses
// or is refused with an InputError naming the file, line and key; anything else (a crash, a sanitizer
// report, another exception escaping) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/scene/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto scene = basalt::solver::parse_scene_text(text, "fuzz.toml", "/nonexistent");
    (void)basalt::solver::field_columns(scene);
  } catch (const basalt::solver::InputError&) {
  }
  return 0;
}
