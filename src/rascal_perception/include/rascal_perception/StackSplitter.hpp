#pragma once
// Sherds lying on each other (a tipped-out bag): one colour blob, several sherds. The depth tells
// them apart: a sherd on another stands a wall higher, so its outline is a step in the height map
// where the colour shows none. StackSplitter cuts a blob along such steps, and says of each part
// how much of its edge runs under a higher neighbour (covered: not to be picked before it) and
// how high the surface it rests on lies (support: where the fingertips may close).
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_perception/SherdMeasurer.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

struct StackPart {
  Blob blob;
  /// [1] share of its edge that runs under a higher part of the same blob, or under the edge of
  /// a neighbour seen on it (an island the steps cut off, too small to be a sherd)
  double covered = 0.0;
  double support = 0.0;  ///< [m] height above the plane of the parts it rests on (0: the table)
};

struct StackOptions {
  double step = 0.0025;  ///< [m] a height step at least this big between pixels 4 px apart is an edge
  int min_area_px = 200; ///< smaller parts are folded into their neighbours
};

class StackSplitter {
 public:
  /// Height above the table plane [m] of every pixel of an aligned depth image (CV_32F; NaN
  /// where the depth is invalid or outside [depth_min, depth_max]).
  static cv::Mat heightMap(const cv::Mat& depth_mm, const CameraView& view, const Eigen::Vector4d& plane,
                           double depth_min, double depth_max);
  /// The parts of `blob` (one part, uncovered, when it shows no step that cuts it apart).
  /// `height` is heightMap's image; empty: the blob as it is.
  std::vector<StackPart> split(const Blob& blob, const cv::Mat& height, const StackOptions& options) const;
  /// For each of `parts` (of every blob of a frame; `group`: which blob each came from), the
  /// share of its outline that runs under a part of another blob lying on it: a sherd's end on
  /// another's, the two cut apart by the segmenter's neck split before the depth was looked at
  /// (split() relates only the parts of one blob). Lying on it, not beside it: higher along the
  /// shared edge and its underside there (its top less its measured wall, `walls` [m]; 0: not
  /// measured, never taken to lie on another) up near the part's top. 0 without `height`.
  static std::vector<double> coveredAcross(const std::vector<const Blob*>& parts, const std::vector<int>& group,
                                           const std::vector<double>& walls, const cv::Mat& height,
                                           const StackOptions& options);
};

}  // namespace rascal_perception
