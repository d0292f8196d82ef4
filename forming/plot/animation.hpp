#pragma once
// The frame sequence of `simform plot` as a movie: Motion JPEG in an AVI container,
// written by OpenCV's own encoder (cv::CAP_OPENCV_MJPEG: no FFmpeg or GStreamer needed,
// so it works with Debian's OpenCV and plays in VLC, ffplay and browsers' download).
#include <string>
#include <vector>

namespace sf::forming {

// Writes `frames` (PNG files of one size, in order) to `path` at `fps` frames per second.
// False (and the reason in *why) when it cannot: built without OpenCV's videoio, a frame
// that cannot be read, or the writer refusing the file; a partial file is removed.
bool write_animation(const std::vector<std::string>& frames, const std::string& path, double fps, std::string* why);

}  // namespace sf::forming
