#include "png_output.hpp"

#include <fmt/format.h>
#include <vtkPNGWriter.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace basalt::view {

namespace fs = std::filesystem;

namespace {

vtkSmartPointer<vtkWindowToImageFilter> grab(vtkRenderWindow& window) {
  auto g = vtkSmartPointer<vtkWindowToImageFilter>::New();
  g->SetInput(&window);
  g->SetInputBufferTypeToRGB();
  g->ReadFrontBufferOff();
  g->Update();
  return g;
}

std::uint32_t crc32(const unsigned char* p, std::size_t n, std::uint32_t crc = 0xffffffffu) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ p[i]) & 0xffu] ^ (crc >> 8);
  return crc;
}

void put32(std::vector<unsigned char>& v, std::uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(static_cast<unsigned char>(x >> s));
}
void put16(std::vector<unsigned char>& v, std::uint16_t x) {
  v.push_back(static_cast<unsigned char>(x >> 8));
  v.push_back(static_cast<unsigned char>(x));
}
std::uint32_t get32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

struct Chunk {
  std::string type;
  std::vector<unsigned char> data;
};

std::vector<Chunk> chunks_of(const std::vector<unsigned char>& png) {
  std::vector<Chunk> out;
  std::size_t at = 8;  // after the signature
  while (at + 12 <= png.size()) {
    const std::uint32_t len = get32(&png[at]);
    if (at + 12 + len > png.size()) break;
    Chunk c;
    c.type.assign(reinterpret_cast<const char*>(&png[at + 4]), 4);
    c.data.assign(png.begin() + static_cast<std::ptrdiff_t>(at + 8),
                  png.begin() + static_cast<std::ptrdiff_t>(at + 8 + len));
    out.push_back(std::move(c));
    at += 12 + len;
  }
  return out;
}

}  // namespace

void write_png(vtkRenderWindow& window, const fs::path& file) {
  auto g = grab(window);
  const fs::path tmp = fs::path(file.string() + ".partial");
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetInputConnection(g->GetOutputPort());
  writer->SetFileName(tmp.c_str());
  writer->SetCompressionLevel(9);
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !fs::exists(tmp, ec) || fs::file_size(tmp, ec) == 0) {
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write {}: the PNG writer failed", file.string()));
  }
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot write {}: {}", file.string(), ec.message()));
  }
}

std::vector<unsigned char> png_bytes(vtkRenderWindow& window) {
  auto g = grab(window);
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetInputConnection(g->GetOutputPort());
  writer->WriteToMemoryOn();
  writer->SetCompressionLevel(9);
  writer->Write();
  vtkUnsignedCharArray* r = writer->GetResult();
  if (writer->GetErrorCode() != 0 || r == nullptr || r->GetNumberOfTuples() == 0)
    throw std::runtime_error("the PNG writer failed (to memory)");
  return {r->GetPointer(0), r->GetPointer(0) + r->GetNumberOfTuples()};
}

AnimatedPng::AnimatedPng(fs::path file, int frames, double fps)
    : file_(std::move(file)), tmp_(file_.string() + ".partial"), frames_(frames) {
  // The frame delay as a fraction delay_num / delay_den seconds.
  delay_den_ = 1000;
  delay_num_ = static_cast<std::uint16_t>(std::lround(1000.0 / fps));
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_)
    throw std::runtime_error(fmt::format("cannot write {}: cannot create {}", file_.string(), tmp_.string()));
}

AnimatedPng::~AnimatedPng() {
  if (!done_) {
    out_.close();
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void AnimatedPng::chunk(const char* type, const std::vector<unsigned char>& data) {
  std::vector<unsigned char> head;
  put32(head, static_cast<std::uint32_t>(data.size()));
  head.insert(head.end(), type, type + 4);
  std::uint32_t crc = crc32(head.data() + 4, 4);
  crc = crc32(data.data(), data.size(), crc) ^ 0xffffffffu;
  std::vector<unsigned char> tail;
  put32(tail, crc);
  out_.write(reinterpret_cast<const char*>(head.data()), static_cast<std::streamsize>(head.size()));
  out_.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  out_.write(reinterpret_cast<const char*>(tail.data()), static_cast<std::streamsize>(tail.size()));
}

void AnimatedPng::add(vtkRenderWindow& window) {
  const std::vector<Chunk> chunks = chunks_of(png_bytes(window));
  if (chunks.empty() || chunks.front().type != "IHDR" || chunks.front().data.size() < 8)
    throw std::runtime_error(fmt::format("cannot write {}: VTK's PNG has no IHDR chunk", file_.string()));
  const std::vector<unsigned char>& ihdr = chunks.front().data;
  if (added_ == 0) {
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    out_.write(reinterpret_cast<const char*>(signature), 8);
    chunk("IHDR", ihdr);
    std::vector<unsigned char> actl;
    put32(actl, static_cast<std::uint32_t>(frames_));
    put32(actl, 0);  // play forever
    chunk("acTL", actl);
  }
  std::vector<unsigned char> fctl;
  put32(fctl, sequence_++);
  put32(fctl, get32(&ihdr[0]));  // width
  put32(fctl, get32(&ihdr[4]));  // height
  put32(fctl, 0);                // x offset
  put32(fctl, 0);                // y offset
  put16(fctl, delay_num_);
  put16(fctl, delay_den_);
  fctl.push_back(0);  // dispose: none
  fctl.push_back(0);  // blend: source
  chunk("fcTL", fctl);
  for (const Chunk& c : chunks) {
    if (c.type != "IDAT") continue;
    if (added_ == 0) {
      chunk("IDAT", c.data);
    } else {
      // The sequence number, then the frame's image data (sized first: GCC 12 warns, wrongly, of an
      // over-read when a 4-byte vector grows by insert in the position-independent build).
      std::vector<unsigned char> fdat(4 + c.data.size());
      const std::uint32_t seq = sequence_++;
      for (int k = 0; k < 4; ++k)
        fdat[static_cast<std::size_t>(k)] = static_cast<unsigned char>(seq >> (24 - 8 * k));
      if (!c.data.empty()) std::memcpy(fdat.data() + 4, c.data.data(), c.data.size());
      chunk("fdAT", fdat);
    }
  }
  ++added_;
  if (!out_)
    throw std::runtime_error(fmt::format("cannot write {}: write failed (disk full?)", tmp_.string()));
}

void AnimatedPng::finish() {
  if (added_ != frames_)
    throw std::runtime_error(
        fmt::format("cannot write {}: {} frames announced, {} drawn", file_.string(), frames_, added_));
  chunk("IEND", {});
  out_.close();
  if (!out_)
    throw std::runtime_error(fmt::format("cannot write {}: write failed (disk full?)", tmp_.string()));
  std::error_code ec;
  fs::rename(tmp_, file_, ec);
  if (ec) throw std::runtime_error(fmt::format("cannot write {}: {}", file_.string(), ec.message()));
  done_ = true;
}

}  // namespace basalt::view
