#include "picture_module.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <system_error>

namespace basalt::run {

namespace fs = std::filesystem;

namespace {

fs::path module_path() {
  if (const char* p = std::getenv("BASALT_RENDER_MODULE"); p != nullptr && *p != '\0') return p;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return (ec ? fs::path(".") : exe.parent_path()) / "basalt-render-insitu.so";
}

}  // namespace

io::Pictures load_picture_module(const io::RenderSpec& spec) {
  io::Pictures out;
  const fs::path file = module_path();
  // Never closed: the writer's code lives in it until the process ends.
  void* handle = ::dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = ::dlerror();
    out.error = fmt::format("in-situ pictures: cannot load the render module {}: {}", file.string(),
                            why ? why : "unknown error");
    return out;
  }
  auto entry = reinterpret_cast<io::PictureModuleEntry>(::dlsym(handle, io::kPictureModuleEntry));
  if (entry == nullptr) {
    out.error = fmt::format("in-situ pictures: {} has no entry point {} (another version of Basalt?)",
                            file.string(), io::kPictureModuleEntry);
    return out;
  }
  std::string error;
  std::unique_ptr<io::PictureWriter> writer(entry(&spec, &error));
  if (!writer) {
    out.error = fmt::format("in-situ pictures: {}", error);
    return out;
  }
  out.draw = std::move(*writer);
  return out;
}

}  // namespace basalt::run
