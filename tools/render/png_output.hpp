#pragma once
#include <vtkRenderWindow.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace basalt::view {

/// Grabs the window's pixels and writes them as PNG, through a temporary name so that a failed
/// write leaves nothing under `file`. Throws std::runtime_error naming the file.
void write_png(vtkRenderWindow& window, const std::filesystem::path& file);

/// The window's pixels as the bytes of a PNG file (VTK's PNG writer, to memory).
std::vector<unsigned char> png_bytes(vtkRenderWindow& window);

/// An animated PNG (APNG: the PNG chunks acTL, fcTL, fdAT), played by browsers and most image viewers
/// and shown as its first frame by any PNG reader. Frames are VTK's own PNG encodings (their IDAT data
/// reused as is), written as they come; the file appears under its name at finish(), and a writer
/// destroyed before that leaves nothing. Throws std::runtime_error naming the file.
class AnimatedPng {
 public:
  AnimatedPng(std::filesystem::path file, int frames, double fps);
  ~AnimatedPng();
  AnimatedPng(const AnimatedPng&) = delete;
  AnimatedPng& operator=(const AnimatedPng&) = delete;
  void add(vtkRenderWindow& window);
  void finish();

 private:
  void chunk(const char* type, const std::vector<unsigned char>& data);
  std::filesystem::path file_, tmp_;
  std::ofstream out_;
  int frames_, added_ = 0;
  std::uint32_t sequence_ = 0;
  std::uint16_t delay_num_ = 1, delay_den_ = 10;
  bool done_ = false;
};

}  // namespace basalt::view
