// A stdlib-only mutation fuzzer for the targets of tools/fuzz (their LLVMFuzzerTestOneInput), for
// compilers without libFuzzer (gcc). No coverage guidance: it mutates the seed files at random (bit
// flips, interesting bytes, tokens of the formats, deleted, repeated and spliced ranges) for a given
// time. A crash (signal) writes the input that caused it before the process dies.
//   fuzz_scene_standalone SECONDS OUT_DIR SEED_FILE_OR_DIR...
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

const std::string* g_current = nullptr;  // the input being run (for the crash handler)
int g_crash_fd = -1;                     // opened before the run: writing it is async-signal-safe

void on_crash(int sig) {
  if (g_crash_fd >= 0 && g_current) {
    const char* p = g_current->data();
    std::size_t left = g_current->size();
    while (left > 0) {
      const ssize_t n = write(g_crash_fd, p, left);
      if (n <= 0) break;
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    fsync(g_crash_fd);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

std::vector<std::string> read_seeds(int argc, char** argv) {
  std::vector<std::string> seeds;
  auto add = [&](const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    seeds.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  for (int k = 3; k < argc; ++k) {
    if (fs::is_directory(argv[k])) {
      for (const auto& e : fs::recursive_directory_iterator(argv[k]))
        if (e.is_regular_file() && e.file_size() < 65536) add(e.path());
    } else if (fs::is_regular_file(argv[k])) {
      add(argv[k]);
    }
  }
  if (seeds.empty()) seeds.emplace_back();
  return seeds;
}

// Tokens of TOML scenes and .geo files, and numbers at the edges of their types.
const char* const kTokens[] = {"[",
                               "]",
                               "[[",
                               "]]",
                               "=",
                               "\"",
                               "{",
                               "}",
                               ",",
                               ".",
                               "\n",
                               " ",
                               "#",
                               "-",
                               "+",
                               "e",
                               "E",
                               "inf",
                               "nan",
                               "-inf",
                               "1e308",
                               "1e-320",
                               "0",
                               "-1",
                               "2147483648",
                               "9223372036854775808",
                               "18446744073709551616",
                               "true",
                               "false",
                               "type",
                               "K",
                               "tags",
                               "every",
                               "wall",
                               "motion",
                               "amplitude",
                               "period",
                               "velocity",
                               "output.fields",
                               "interactions",
                               "walls",
                               "run",
                               "dt",
                               "steps",
                               "skin",
                               "BeginParticles",
                               "EndParticles",
                               "BeginConnect",
                               "EndConnect",
                               "Simple",
                               "LSMGeometry 1.2",
                               "\r",
                               "\t",
                               "\xff",
                               "\0"};

std::string mutate(const std::vector<std::string>& seeds, std::mt19937_64& rng) {
  auto pick = [&](std::size_t n) { return n == 0 ? std::size_t{0} : std::size_t(rng() % n); };
  std::string s = seeds[pick(seeds.size())];
  const int rounds = 1 + int(rng() % 8);
  for (int r = 0; r < rounds; ++r) {
    const std::size_t at = pick(s.size() + 1);
    switch (rng() % 7) {
      case 0:  // flip a bit
        if (!s.empty()) s[pick(s.size())] ^= char(1u << (rng() % 8));
        break;
      case 1:  // an interesting byte
        if (!s.empty()) s[pick(s.size())] = "09-.e[]\"=\n \xff\x00"[rng() % 14];
        break;
      case 2: {  // insert a token
        const char* t = kTokens[pick(std::size(kTokens))];
        s.insert(at, std::string(t, t[0] ? std::char_traits<char>::length(t) : 1));
        break;
      }
      case 3:  // delete a range
        s.erase(at, pick(32) + 1);
        break;
      case 4: {  // repeat a range
        if (s.empty()) break;
        const std::size_t from = pick(s.size()), len = std::min<std::size_t>(pick(64) + 1, s.size() - from);
        s.insert(at, s.substr(from, len));
        break;
      }
      case 5: {  // splice another seed
        const std::string& o = seeds[pick(seeds.size())];
        const std::size_t from = pick(o.size() + 1);
        s.insert(at, o.substr(from, pick(256) + 1));
        break;
      }
      case 6:  // replace a digit run by another number
        if (!s.empty()) {
          std::size_t p = pick(s.size());
          while (p < s.size() && !(s[p] >= '0' && s[p] <= '9')) ++p;
          std::size_t q = p;
          while (q < s.size() && ((s[q] >= '0' && s[q] <= '9') || s[q] == '.')) ++q;
          if (p < s.size()) s.replace(p, q - p, kTokens[17 + pick(7)]);
        }
        break;
    }
  }
  if (s.size() > 65536) s.resize(65536);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s SECONDS OUT_DIR SEED_FILE_OR_DIR...\n", argv[0]);
    return 2;
  }
  const double seconds = std::atof(argv[1]);
  const fs::path out = argv[2];
  fs::create_directories(out);
  const auto seeds = read_seeds(argc, argv);
  const std::string crash = (out / "crash-input").string();
  g_crash_fd = open(crash.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  for (int sig : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) std::signal(sig, on_crash);
  std::mt19937_64 rng(std::random_device{}());
  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t runs = 0;
  for (const auto& s : seeds) {  // every seed as it is first
    g_current = &s;
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
    ++runs;
  }
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < seconds) {
    const std::string s = mutate(seeds, rng);
    g_current = &s;
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
    ++runs;
  }
  g_current = nullptr;
  close(g_crash_fd);
  fs::remove(crash);  // no crash: nothing to keep
  std::printf("%llu inputs in %.0f s (%zu seeds), no crash\n", static_cast<unsigned long long>(runs), seconds,
              seeds.size());
  return 0;
}
