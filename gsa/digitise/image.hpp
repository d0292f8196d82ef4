#pragma once
// Grey images as plain data (OpenCV stays in the .cpp files).

#include <string>
#include <vector>

namespace sf::gsa::digitise {

// Row-major grey levels in [0, 1] (an 8-bit image's 255 is 1).
struct GreyImage {
  int width = 0, height = 0;
  std::vector<float> pixels;  // height x width

  GreyImage() = default;
  GreyImage(int w, int h, float value = 0.0f)
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), value) {}
  float& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  float at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
  bool empty() const { return pixels.empty(); }
};

// An image with the name used in messages (usually its path).
struct NamedImage {
  std::string name;
  GreyImage image;
};

// Reads an image file (PNG, TIFF, JPEG, BMP, PGM; 8 or 16 bits; colour is converted to
// grey). Throws sf::InputError "PATH: cannot read image (no such file)" or "PATH: cannot
// read image (not an image format OpenCV reads, or a damaged file)".
GreyImage read_image(const std::string& path);

// Writes an 8-bit (bits = 8) or 16-bit (bits = 16) grey PNG atomically. Throws sf::Error
// naming the path on failure.
void write_png(const std::string& path, const GreyImage& image, int bits = 8);

}  // namespace sf::gsa::digitise
