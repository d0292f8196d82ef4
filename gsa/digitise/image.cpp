#include "gsa/digitise/image.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"

namespace sf::gsa::digitise {

namespace {

// OpenCV's image codecs are loaded when an image is first read or written, not when gsa
// starts: libopencv_imgcodecs pulls in GDAL and about 120 more libraries, whose loading
// and relocation took 0.06 s of processor time at every start of gsa (measured: a
// program linked with it alone, 63 ms against 7 ms with the other OpenCV modules),
// though only calibrate, digitise and synth-images use them. The two functions are looked
// up by their C++ (Itanium ABI) names; their types are checked against the header here.
using Imread = cv::Mat (*)(const cv::String&, int);
using Imencode = bool (*)(const cv::String&, cv::InputArray, std::vector<uchar>&, const std::vector<int>&);
static_assert(std::is_same_v<Imread, decltype(static_cast<Imread>(&cv::imread))>);
static_assert(std::is_same_v<Imencode, decltype(static_cast<Imencode>(&cv::imencode))>);

struct Codecs {
  Imread imread = nullptr;
  Imencode imencode = nullptr;
};

const Codecs& codecs() {
  static const Codecs loaded = [] {
    // The library gsa was built against (CMake passes its file and its soname).
    void* lib = nullptr;
    std::string why;
    for (const char* name : {SF_OPENCV_IMGCODECS_FILE, SF_OPENCV_IMGCODECS_SONAME}) {
      lib = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (lib) break;
      if (const char* e = dlerror()) why += std::string(why.empty() ? "" : "; ") + e;
    }
    if (!lib)
      throw Error("cannot load OpenCV's image codecs (" + why +
                  "); install libopencv-imgcodecs (scripts/install_deps.sh)");
    Codecs c;
    c.imread =
        reinterpret_cast<Imread>(dlsym(lib, "_ZN2cv6imreadERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEEi"));
    c.imencode = reinterpret_cast<Imencode>(dlsym(lib,
                                                  "_ZN2cv8imencodeERKNSt7__cxx1112basic_stringIcSt11char_"
                                                  "traitsIcESaIcEEERKNS_11_InputArrayERSt6vectorIhSaIhEERKSB_"
                                                  "IiSaIiEE"));
    if (!c.imread || !c.imencode)
      throw Error(std::string("OpenCV's image codecs lack cv::imread or cv::imencode (") + SF_OPENCV_IMGCODECS_SONAME +
                  ": another OpenCV than gsa was built against?)");
    return c;
  }();
  return loaded;
}

}  // namespace

GreyImage read_image(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": cannot read image (no such file)");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path + ": cannot read image (it is a folder)");
  cv::Mat m;
  try {
    m = codecs().imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE);
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
  if (!codecs().imencode(".png", q, bytes, std::vector<int>())) throw Error(path + ": cannot encode the PNG image");
  io::write_file_atomic(path, std::string(bytes.begin(), bytes.end()));
}

}  // namespace sf::gsa::digitise
