#pragma once
// Draws detections over the colour image: outlines, oriented boxes, the grasp's finger line, and
// a label with the rank, size and height.
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_perception/Types.hpp"

namespace rascal_perception {

class Annotator {
 public:
  /// RGB in, RGB out; `fixture` (CV_8U, may be empty) is shaded.
  static cv::Mat draw(const cv::Mat& rgb, const std::vector<SherdDetection>& sherds, const cv::Mat& fixture = cv::Mat());
};

}  // namespace rascal_perception
