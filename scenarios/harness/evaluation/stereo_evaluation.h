#pragma once
// Stereo against ground-truth depth: the depth of the original (distorted) left image, as a
// renderer or a depth sensor gives it, carried into the rectified frame as disparity, and the
// usual error figures of an estimated disparity image. Needs no simulator.
#include <opencv2/core.hpp>

#include "trimbot/perception/stereo.h"

namespace trimbot::scenarios {

// Ground-truth disparity (CV_32F, px) of the rectified left image, NaN where there is none.
// `depth` is of the original left image: CV_32F metres along the optical axis, 0 = no depth.
// Each rectified pixel samples the original pixel it was resampled from (nearest), whose 3D
// point is rotated into the rectified frame: d = f B / Z_rectified.
// std::invalid_argument if `depth` is not CV_32F of the calibrated size.
cv::Mat GroundTruthDisparity(const perception::StereoRectifier& rectifier, const cv::Mat& depth);

struct StereoErrors {
  double mean_abs_error = 0.0;  // px, over evaluated pixels
  double bad1_percent = 0.0;    // % of evaluated pixels with error > 1 px
  double bad2_percent = 0.0;    // % of evaluated pixels with error > 2 px
  // % of the pixels with ground truth inside the disparity range (and a match inside the right
  // image, u - d >= 0) that have an estimate.
  double completeness_percent = 0.0;
  int evaluated_pixels = 0;     // estimate and ground truth in range
  int ground_truth_pixels = 0;  // ground truth in range
  // Estimates where there is nothing to see (no ground-truth depth, e.g. sky): false points in
  // the cloud. % of all estimates.
  double spurious_percent = 0.0;
};

// `estimate` and `ground_truth` as from StereoMatcher::Compute and GroundTruthDisparity; the
// disparity range is [0, disparities - 1] px. std::invalid_argument on mismatched images.
StereoErrors EvaluateDisparity(const cv::Mat& estimate, const cv::Mat& ground_truth, int disparities);

}  // namespace trimbot::scenarios
