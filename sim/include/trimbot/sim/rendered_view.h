#pragma once
// One rendered camera view: the image and, on request, the renderer's ground truth for it.
#include <opencv2/core.hpp>

namespace trimbot::sim {

struct RenderedView {
  cv::Mat rgb;           // CV_8UC3, RGB order, calibrated (distorted) image
  cv::Mat depth;         // CV_32F, metres along the optical axis; 0 where nothing was hit
  cv::Mat object_class;  // CV_8U, garden::ObjectClass
  cv::Mat object_id;     // CV_16U, garden object id (see garden/object_class.h)
};

}  // namespace trimbot::sim
