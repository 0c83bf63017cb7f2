#pragma once
// The 10 cm x 2 cm scale bar found by its pattern: one half a chequerboard of 1 cm squares in two
// rows, the other half solid (one row black, one row white). Found at any rotation and partly
// shadowed; px/cm from the chequer's pitch (same-direction edges, so white bloom cancels), the
// bar's ends only as a cross-check.
#include <opencv2/core.hpp>
#include <string>

namespace rascal_perception {

struct ScaleBar {
  bool found = false;
  cv::RotatedRect box;       ///< the whole bar, in image pixels
  double px_per_cm = 0.0;    ///< from the chequer pitch (or the ends when the chequer is unreadable)
  double pitch_spread = 0.0; ///< relative spread of the pitch measurements (0.01 = 1 %)
  int squares = 0;           ///< chequer squares that agreed
  double ends_px_per_cm = 0.0;  ///< from the bar's end-to-end length, a cross-check (0: ends unclear)
  std::string doubt;         ///< empty when trusted; else one line (e.g. "only the bar's ends")
};

struct ScaleBarOptions {
  double bar_length_cm = 10.0;  ///< the printed bar; 1 cm squares, 2 cm wide
};

/// The scale bar in an RGB photo; `found` false when no bar pattern is in view.
ScaleBar findScaleBar(const cv::Mat& rgb, const ScaleBarOptions& options = ScaleBarOptions());

}  // namespace rascal_perception
