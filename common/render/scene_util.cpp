// The small parts of scene.hpp: option parsing, pixel mapping, reading PNG files back.
#include "common/render/scene.hpp"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "common/core/error.hpp"

namespace sf::render {

View parse_view(const std::string& text, const std::string& option) {
  View v;
  if (text == "auto")
    v.kind = ViewKind::kAuto;
  else if (text == "iso")
    v.kind = ViewKind::kIso;
  else if (text == "top")
    v.kind = ViewKind::kTop;
  else if (text == "front")
    v.kind = ViewKind::kFront;
  else if (text == "side")
    v.kind = ViewKind::kSide;
  else {
    std::stringstream ss(text);
    std::string item;
    std::vector<double> xyz;
    bool ok = true;
    while (std::getline(ss, item, ',')) {
      try {
        std::size_t used = 0;
        xyz.push_back(std::stod(item, &used));
        if (used != item.size()) ok = false;
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok || xyz.size() != 3 || !std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2]) ||
        Vec3(xyz[0], xyz[1], xyz[2]).norm() == 0)
      throw UsageError(option +
                       ": expected auto, iso, top, front, side or a view direction x,y,z "
                       "(e.g. 1,-1,2), found '" +
                       text + "'");
    v.kind = ViewKind::kDirection;
    v.direction = Vec3(xyz[0], xyz[1], xyz[2]);
  }
  return v;
}

std::string view_name(const View& v) {
  switch (v.kind) {
    case ViewKind::kAuto:
      return "auto (along the mean normal)";
    case ViewKind::kIso:
      return "iso";
    case ViewKind::kTop:
      return "top";
    case ViewKind::kFront:
      return "front";
    case ViewKind::kSide:
      return "side";
    case ViewKind::kDirection: {
      std::ostringstream os;
      os << "from (" << v.direction.x() << ", " << v.direction.y() << ", " << v.direction.z() << ")";
      return os.str();
    }
  }
  return "auto";
}

ImageSize parse_size(const std::string& text, const std::string& option) {
  const auto x = text.find_first_of("xX");
  ImageSize s;
  try {
    if (x == std::string::npos) throw std::invalid_argument(text);
    std::size_t u1 = 0, u2 = 0;
    const std::string a = text.substr(0, x), b = text.substr(x + 1);
    s.width = std::stoi(a, &u1);
    s.height = std::stoi(b, &u2);
    if (u1 != a.size() || u2 != b.size()) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw UsageError(option + ": expected WIDTHxHEIGHT in pixels (e.g. 1200x900), found '" + text + "'");
  }
  if (s.width < 200 || s.height < 200 || s.width > 8000 || s.height > 8000)
    throw UsageError(option + ": width and height must be between 200 and 8000 pixels, found '" + text + "'");
  return s;
}

Vec2 Framing::to_pixel(const Vec3& p) const {
  const Vec3 d = p - focal;
  const double x = width / 2.0 + d.dot(right) * pixels_per_unit;
  const double y = height / 2.0 + d.dot(up) * pixels_per_unit;
  return {x, height - y};
}

Colour RgbImage::at(int x, int y) const {
  if (x < 0 || y < 0 || x >= width || y >= height) return {};
  const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
  return Colour::from_rgb8(pixels[i], pixels[i + 1], pixels[i + 2]);
}

RgbImage read_png_rgb(const std::string& path) {
  vtkNew<vtkPNGReader> reader;
  if (!std::filesystem::exists(path) || !reader->CanReadFile(path.c_str())) throw Error(path + ": cannot read PNG");
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  const int nc = img->GetNumberOfScalarComponents();
  if (dims[0] <= 0 || dims[1] <= 0 || nc < 3 || img->GetScalarType() != VTK_UNSIGNED_CHAR)
    throw Error(path + ": cannot read PNG");
  RgbImage out;
  out.width = dims[0];
  out.height = dims[1];
  out.pixels.resize(static_cast<std::size_t>(out.width) * out.height * 3);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      const auto* p = static_cast<const unsigned char*>(img->GetScalarPointer(x, out.height - 1 - y, 0));
      const std::size_t i = (static_cast<std::size_t>(y) * out.width + x) * 3;
      for (int c = 0; c < 3; ++c) out.pixels[i + c] = p[c];
    }
  return out;
}

}  // namespace sf::render
