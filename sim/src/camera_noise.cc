#include "trimbot/sim/camera_noise.h"

#include <algorithm>
#include <stdexcept>

namespace trimbot::sim {

ReadNoise::ReadNoise(std::uint64_t seed, std::size_t bank_size) : bank_(bank_size) {
  if (bank_size == 0) throw std::invalid_argument("ReadNoise: empty bank");
  cv::RNG rng(seed);  // OpenCV's own generator: the same samples on every platform
  cv::Mat samples(1, static_cast<int>(bank_size), CV_32F, bank_.data());
  rng.fill(samples, cv::RNG::NORMAL, 0.0, 1.0);
}

void ReadNoise::Apply(cv::Mat& rgb, double sigma, std::uint64_t image_seed) const {
  if (rgb.type() != CV_8UC3) throw std::invalid_argument("ReadNoise: expects an 8-bit RGB image");
  if (sigma <= 0.0) return;
  const auto s = static_cast<float>(sigma);
  std::size_t k = static_cast<std::size_t>(image_seed % bank_.size());
  for (int r = 0; r < rgb.rows; ++r) {
    uchar* row = rgb.ptr<uchar>(r);
    const auto n = static_cast<std::size_t>(rgb.cols) * 3;
    for (std::size_t i = 0; i < n;) {
      const std::size_t run = std::min(n - i, bank_.size() - k);  // up to the bank's end, then wrap
      const float* noise = bank_.data() + k;
      for (std::size_t j = 0; j < run; ++j) row[i + j] = cv::saturate_cast<uchar>(row[i + j] + s * noise[j]);
      i += run;
      k = (k + run) % bank_.size();
    }
  }
}

}  // namespace trimbot::sim
