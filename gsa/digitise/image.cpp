#include "gsa/digitise/image.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::gsa::digitise {

GreyImage read_image(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": cannot read image (no such file)");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": cannot read image (it is a folder)");
  cv::Mat m;
  try {
    m = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw InputError(path + ": cannot read image (" + e.msg + ")");
  }
  if (m.empty()) throw InputError(path + ": cannot read image (not an image format OpenCV reads, or a damaged file)");
  double scale = 1.0;
  switch (m.depth()) {
    case CV_8U:
      scale = 1.0 / 255.0;
      break;
    case CV_16U:
      scale = 1.0 / 65535.0;
      break;
    case CV_32F:
      scale = 1.0;
      break;
    default:
      throw InputError(path + ": cannot read image (unsupported pixel depth; use 8- or 16-bit images)");
  }
  GreyImage out(m.cols, m.rows);
  cv::Mat f(m.rows, m.cols, CV_32F, out.pixels.data());
  m.convertTo(f, CV_32F, scale);
  return out;
}

void write_png(const std::string& path, const GreyImage& image, int bits) {
  if (bits != 8 && bits != 16) throw std::logic_error("write_png: bits must be 8 or 16");
  cv::Mat f(image.height, image.width, CV_32F, const_cast<float*>(image.pixels.data()));
  cv::Mat q;
  f.convertTo(q, bits == 8 ? CV_8U : CV_16U, bits == 8 ? 255.0 : 65535.0);  // rounds and saturates
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", q, bytes)) throw Error(path + ": cannot encode the PNG image");
  io::write_file_atomic(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace sf::gsa::digitise
