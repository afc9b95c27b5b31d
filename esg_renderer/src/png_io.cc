#include "rms/esg_renderer/png_io.h"

#include <png.h>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "rms/base/folder_file.h"

namespace rms::esg_renderer {

namespace {
struct FileCloser {
  void operator()(FILE* f) const {
    if (f) std::fclose(f);
  }
};

// Encodes RGBA rows as an RGB PNG (compression level 1, SUB filter) to
// where `set_io` points libpng. Throws std::runtime_error naming `what`.
template <typename SetIo>
void EncodeRgbaPng(int width, int height, const std::uint8_t* rgba, const std::string& what,
                   SetIo&& set_io) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng: out of memory");
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("libpng failed writing " + what);
  }
  set_io(png);
  png_set_compression_level(png, 1);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
  png_write_info(png, info);
  png_set_filler(png, 0, PNG_FILLER_AFTER);  // input rows are RGBA; drop A
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(rgba + static_cast<std::size_t>(y) * width * 4));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
}

}  // namespace

void WritePng(const std::string& path, int width, int height, const std::uint8_t* rgba) {
  std::unique_ptr<FILE, FileCloser> f(std::fopen(path.c_str(), "wb"));
  if (!f) throw std::runtime_error("cannot write PNG '" + path + "'");
  EncodeRgbaPng(width, height, rgba, "'" + path + "'",
                [&f](png_structp png) { png_init_io(png, f.get()); });
}

std::vector<std::uint8_t> EncodePng(int width, int height, const std::uint8_t* rgba) {
  std::vector<std::uint8_t> out;
  EncodeRgbaPng(width, height, rgba, "a PNG in memory", [&out](png_structp png) {
    png_set_write_fn(
        png, &out,
        [](png_structp p, png_bytep data, png_size_t n) {
          auto* v = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(p));
          v->insert(v->end(), data, data + n);
        },
        [](png_structp) {});
  });
  return out;
}

Image ReadPng(const std::string& path) {
  // A regular file of bounded size (docs/security.md "Session folders are
  // untrusted"), of bounded dimensions.
  const std::string bytes = ReadRegularFile(path, "a PNG", kMaxPngBytes);
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size())) {
    throw std::runtime_error("cannot read PNG '" + path + "': " + img.message);
  }
  if (img.width > 8192 || img.height > 8192) {
    png_image_free(&img);
    throw std::runtime_error("cannot read PNG '" + path + "': larger than 8192 x 8192");
  }
  img.format = PNG_FORMAT_RGB;
  Image out;
  out.width = static_cast<int>(img.width);
  out.height = static_cast<int>(img.height);
  out.rgb.resize(PNG_IMAGE_SIZE(img));
  if (!png_image_finish_read(&img, nullptr, out.rgb.data(), 0, nullptr)) {
    png_image_free(&img);
    throw std::runtime_error("cannot decode PNG '" + path + "': " + img.message);
  }
  return out;
}

}  // namespace rms::esg_renderer
