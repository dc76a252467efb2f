#include "output_folder.hpp"

#include <fmt/format.h>

#include <fstream>
#include <optional>
#include <string>

#include "basalt/solver/core/errors.hpp"
#include "basalt/solver/parallel/communicator.hpp"

namespace basalt::run {

namespace fs = std::filesystem;

void prepare_output_folder(const fs::path& dir, MPI_Comm world) {
  const solver::Comm comm(world);
  std::optional<std::string> error;
  if (comm.rank() == 0) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
      error = fmt::format("{}: cannot create the output folder: {}", dir.string(), ec.message());
    } else {
      const fs::path probe = dir / ".basalt-write-probe";
      std::ofstream f(probe);
      if (!f || !(f << "ok\n") || !f.flush())
        error = fmt::format("{}: the output folder is not writable", dir.string());
      f.close();
      fs::remove(probe, ec);
    }
  }
  if (auto e = comm.agree_error(error)) throw solver::InputError(*e);
}

}  // namespace basalt::run
