#pragma once
// A sherd's wall thickness from the depth of its top surface, as it lies on the table.
//
// A sherd is a piece of a shell. Lying on its outer face (concave side up) its top surface is
// lowest in the middle, where the wall stands on the table; lying on its inner face (convex side
// up) it is lowest at the edge it rests on. Either way the lowest point of the top surface is
// one wall thickness above the table, while the highest point (the sherd's height as it lies)
// adds the curvature's sagitta. A quadric fitted to the top surface's heights (the shell's
// curvature and tilt) gives that lowest point without the depth noise of single pixels and
// without the mixed depths at the outline. Error model: package README, "Wall thickness".
// No ROS.

#include <string>
#include <vector>

namespace rascal_perception {

/// One depth pixel of a sherd's top surface: where it is in the table plane and how high.
struct TopSample {
  double x = 0.0, y = 0.0;  ///< [m] in the table plane (base_link x, y)
  double h = 0.0;           ///< [m] above the table plane
  bool interior = false;    ///< away from the outline (its depth is not mixed with the table's)
};

struct WallThickness {
  bool valid = false;
  double thickness = 0.0;  ///< [m] lowest point of the fitted top surface above the table
  double rms = 0.0;        ///< [m] residual of the fit: how far the top is from a smooth shell
  int samples = 0;         ///< interior samples the fit used
  std::string why;         ///< when not valid: what was wrong

  /// Fewer interior samples than this: too small a sherd (or too little depth) to fit.
  static constexpr int kMinSamples = 40;
  /// [m] a top surface further than this from a quadric is no plain shell (a rim, a handle, a
  /// foot, two sherds on each other): no thickness is claimed.
  static constexpr double kMaxRms = 0.0012;

  /// Fits h = quadric(x, y) to the interior samples (twice: the second time without the samples
  /// more than 3 RMS off), then takes its lowest value over every sample's (x, y), clamped to
  /// [0, highest sample].
  static WallThickness estimate(const std::vector<TopSample>& samples);
};

}  // namespace rascal_perception
