#include "io_test_util.hpp"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>

namespace basalt::io::test {

Geometry sample_geometry() {
  Geometry g;
  g.add_particle(40, {1.5, 2.25, 3.0}, 0.5, 1);
  g.add_particle(3, {0.1, 0.2, 0.30000000000000004}, 0.25, 2);
  g.add_particle(17, {4.0, 4.0, 4.0}, 1.0, 1);
  g.add_particle(8, {2.0, 1.0, 0.5}, 0.75, 3);
  g.add_particle(99, {9.0, 8.5, 7.125}, 0.2, 0);
  g.add_particle(5, {-1.0, 1e-300, 6.02214076e23}, 0.3, -4);
  g.mass = {1.0, 2.0, 3.5, 4.0, 5.0, 6.0};
  g.add_bond(3, 8, 1);
  g.add_bond(40, 17, 2);  // stored smaller id first on write
  g.add_bond(5, 99, 0);
  g.add_bond(8, 40, 7);
  g.box_min = {-1.5, 0, 0};
  g.box_max = {10, 10, 7.5e23};
  g.periodic = {true, false, true};
  g.units = {"m", "s", "kN", "kg"};
  g.attributes = {{"creator", "basalt-pack"}, {"seed", "42"}, {"command_line", "basalt-pack --size 15"}};
  g.statistics = {{"solid_fraction", {0.685}}, {"radius_histogram_counts", {1, 2, 3, 4}}, {"empty", {}}};
  return g;
}

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void expect_format_error(const std::function<void()>& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "expected a FormatError mentioning '" << *fragments.begin() << "', nothing was thrown";
  } catch (const FormatError& e) {
    const std::string msg = e.what();
    if (std::getenv("BASALT_TEST_SHOW_ERRORS")) std::printf("    error: %s\n", msg.c_str());
    for (const auto& frag : fragments)
      EXPECT_NE(msg.find(frag), std::string::npos) << "message '" << msg << "' lacks '" << frag << "'";
  }
}

void expect_same_particles_and_bonds(const Geometry& a, const Geometry& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.position, b.position);  // exact doubles
  EXPECT_EQ(a.radius, b.radius);
  EXPECT_EQ(a.tag, b.tag);
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.bonds, b.bonds);
}

}  // namespace basalt::io::test
