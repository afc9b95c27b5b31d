#pragma once
// PNG files through libpng: fast writes (compression level 1, SUB filter) for
// frames, and reads for tests and tools.
#include <cstdint>
#include <string>
#include <vector>

namespace rms::esg_renderer {

// Writes RGBA (rows top to bottom) as an RGB PNG. Throws std::runtime_error.
void WritePng(const std::string& path, int width, int height, const std::uint8_t* rgba);
// The same PNG in memory (for a web page's image). Throws std::runtime_error.
std::vector<std::uint8_t> EncodePng(int width, int height, const std::uint8_t* rgba);

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // 3 bytes a pixel, rows top to bottom
  const std::uint8_t* at(int x, int y) const {
    return &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
  }
};
// Reads an 8-bit RGB or RGBA PNG. Throws std::runtime_error.
Image ReadPng(const std::string& path);

}  // namespace rms::esg_renderer
