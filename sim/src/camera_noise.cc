#include "trimbot/sim/camera_noise.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <stdexcept>

namespace trimbot::sim {

ReadNoise::ReadNoise(std::uint64_t seed, std::size_t bank_size) : bank_(bank_size) {
  if (bank_size == 0) throw std::invalid_argument("ReadNoise: empty bank");
  cv::RNG rng(seed);  // OpenCV's own generator: the same samples on every platform
  cv::Mat samples(1, static_cast<int>(bank_size), CV_32F, bank_.data());
  rng.fill(samples, cv::RNG::NORMAL, 0.0, 1.0);
}

void ReadNoise::ReadOut(cv::Mat& rgb, double signal_scale, double sigma, std::uint64_t image_seed) const {
  if (rgb.type() != CV_8UC3) throw std::invalid_argument("ReadNoise: expects an 8-bit RGB image");
  if (sigma <= 0.0) {
    if (signal_scale != 1.0) rgb.convertTo(rgb, CV_8UC3, signal_scale);
    return;
  }
  if (!rgb.isContinuous()) rgb = rgb.clone();
  // The image as one row of values, the noise as windows of the bank (up to its end, then from its
  // start); OpenCV's addWeighted rounds and saturates like saturate_cast, in SIMD.
  cv::Mat values = rgb.reshape(1, 1);
  std::size_t k = static_cast<std::size_t>(image_seed % bank_.size());
  for (int done = 0; done < values.cols;) {
    const int run = static_cast<int>(std::min<std::size_t>(values.cols - done, bank_.size() - k));
    cv::Mat part = values.colRange(done, done + run);
    const cv::Mat noise(1, run, CV_32F, const_cast<float*>(bank_.data() + k));
    cv::addWeighted(part, signal_scale, noise, sigma, 0.0, part, CV_8U);
    done += run;
    k = (k + run) % bank_.size();
  }
}

}  // namespace trimbot::sim
