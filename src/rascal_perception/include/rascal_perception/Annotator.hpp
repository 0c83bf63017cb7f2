#pragma once
// Draws detections over the colour image: outlines, oriented boxes, the grasp's finger line, and
// a label with the rank, size and height.
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_perception/SherdMeasurer.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

class Annotator {
 public:
  /// RGB in, RGB out; `fixture` (CV_8U, may be empty) is shaded. With `view`, the finger line is
  /// the grasp's (projected at the sherd's top); without, it crosses the image box's minor axis.
  static cv::Mat draw(const cv::Mat& rgb, const std::vector<SherdDetection>& sherds, const cv::Mat& fixture = cv::Mat(),
                      const CameraView* view = nullptr);
};

}  // namespace rascal_perception
