#pragma once
// The cameras' read noise: additive Gaussian per pixel and channel. Drawing a million Gaussian
// samples per full-resolution image cost more than distorting it (4 ms a camera); instead the
// simulator draws a bank of unit samples once, from its seed, and each image takes a window of it
// chosen by the image's own stream seed, scaled by sigma. Windows start anywhere in a bank of 4M
// samples (nearly four full 752x480 RGB images), so neighbouring images' noise is not aligned.
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace trimbot::sim {

class ReadNoise {
 public:
  explicit ReadNoise(std::uint64_t seed, std::size_t bank_size = std::size_t{1} << 22);
  // Reads a rendered image out as the sensor does: the signal scaled by the exposure and gain
  // (`signal_scale`), plus Gaussian noise of `sigma` grey levels from the window `image_seed` picks,
  // rounded and clipped to 0..255 once, as the converter does (noise on a saturated pixel is
  // clipped too). `rgb` is CV_8UC3, changed in place. The same image seed, the same noise.
  void ReadOut(cv::Mat& rgb, double signal_scale, double sigma, std::uint64_t image_seed) const;

 private:
  std::vector<float> bank_;  // unit normal samples
};

}  // namespace trimbot::sim
