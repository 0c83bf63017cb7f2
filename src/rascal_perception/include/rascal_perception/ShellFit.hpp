#pragma once
// A sherd's wall thickness and its vessel's diameter from the depth of its top surface, as it
// lies on the table.
//
// A sherd is a piece of a shell. Lying on its outer face (concave side up) its top surface is
// lowest in the middle, where the wall stands on the table; lying on its inner face (convex side
// up) it is lowest at the edge it rests on. Either way the lowest point of the top surface is
// one wall thickness above the table, while the highest point (the sherd's height as it lies)
// adds the curvature's sagitta. A quadric fitted to the top surface's heights (the shell's
// curvature and tilt) gives that lowest point without the depth noise of single pixels and
// without the mixed depths at the outline, and its strongest curvature is the vessel's: a
// body sherd curves most around the vessel's axis. Error model: package README, "ShellFit".
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

struct ShellFit {
  bool valid = false;      ///< a smooth shell was fitted: thickness is measured
  double thickness = 0.0;  ///< [m] lowest point of the fitted top surface above the table
  double rms = 0.0;        ///< [m] residual of the fit: how far the top is from a smooth shell
  int samples = 0;         ///< interior samples the fit used
  std::string why;         ///< when not valid: what was wrong

  /// [m] the vessel's outer diameter where the sherd comes from, 0 when the sherd is too flat
  /// or too small to tell (diameter_why says which); diameter_sigma [m] its 1-sigma uncertainty.
  double diameter = 0.0, diameter_sigma = 0.0;
  bool concave_up = false;  ///< lying on its outer face (its inside up)
  std::string diameter_why;

  /// Fewer interior samples than this: too small a sherd (or too little depth) to fit.
  static constexpr int kMinSamples = 40;
  /// [m] a top surface further than this from a quadric is no plain shell (a rim, a handle, a
  /// foot, two sherds on each other): no thickness is claimed.
  static constexpr double kMaxRms = 0.0012;
  /// A diameter is reported only within this relative uncertainty (1 sigma) ...
  static constexpr double kMaxRelativeSigma = 0.15;
  /// ... and up to this [m]: flatter than a 1.2 m storage jar is "flat" here ...
  static constexpr double kMaxDiameter = 1.2;
  /// ... and when the curve is at least this deep [m] over the sherd's extent along it (its
  /// sagitta): three quarters of the D435's depth unit (../shared/facts §4.4, 1 mm). Averaged
  /// over hundreds of pixels a curve a little shallower than one step still shows; a much
  /// shallower one is decided by the fit's shape error (seeds 1-50: within 15 % on 93 % of those
  /// told without this rule, 97 % with it, 75 % of the curved told; 1 mm: 97 %, 69 %).
  static constexpr double kMinSagitta = 0.00075;
  /// ... and when the curvature across the strongest is at most this share of it: a body sherd
  /// curves most around the vessel's axis, but a shoulder or a neck curves both ways alike,
  /// and then which way is the circumference cannot be told from the shape.
  static constexpr double kMaxCrossCurvature = 0.5;

  /// Fits h = quadric(x, y) to the interior samples (twice: the second time without the samples
  /// more than 3 RMS off); thickness = its lowest value over every sample's (x, y), clamped to
  /// [0, highest sample]; the diameter from its strongest curvature (the top surface is the
  /// outer face when convex, the inner one, a wall thickness smaller, when concave).
  static ShellFit estimate(const std::vector<TopSample>& samples);
};

}  // namespace rascal_perception
