#include "forming/plot/animation.hpp"

#include <filesystem>

#ifdef SF_HAVE_VIDEOIO
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#endif

namespace sf::forming {

bool write_animation(const std::vector<std::string>& frames, const std::string& path, double fps, std::string* why) {
#ifdef SF_HAVE_VIDEOIO
  if (frames.empty()) {
    if (why) *why = "no frames";
    return false;
  }
  const cv::Mat first = cv::imread(frames.front(), cv::IMREAD_COLOR);
  if (first.empty()) {
    if (why) *why = frames.front() + ": cannot read the frame";
    return false;
  }
  const std::string partial = path + ".partial.avi";
  bool ok = true;
  {
    cv::VideoWriter writer(partial, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                           first.size(), true);
    if (!writer.isOpened()) {
      if (why) *why = "OpenCV's Motion JPEG writer could not open " + partial;
      ok = false;
    }
    for (std::size_t i = 0; ok && i < frames.size(); ++i) {
      const cv::Mat f = i == 0 ? first : cv::imread(frames[i], cv::IMREAD_COLOR);
      if (f.empty() || f.size() != first.size()) {
        if (why) *why = frames[i] + ": cannot read the frame or its size differs";
        ok = false;
        break;
      }
      writer.write(f);
    }
  }
  std::error_code ec;
  if (ok) std::filesystem::rename(partial, path, ec);
  if (!ok || ec) {
    std::filesystem::remove(partial, ec);
    if (ok && why) *why = "cannot move " + partial + " to " + path;
    return false;
  }
  return true;
#else
  (void)frames;
  (void)path;
  (void)fps;
  if (why) *why = "simform was built without OpenCV's videoio module";
  return false;
#endif
}

}  // namespace sf::forming
