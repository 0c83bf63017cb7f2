#pragma once
// How likely a grasped sherd is to slip out of the fingers once lifted: the simulator's model
// (a simulator choice, not a measured figure), one place for the simulator and for the tests
// that ask what a grasp would cost.
//
//   p = 0.02 + 0.5 off^2 + 0.6 along^2 min(1, 2.5 elongation)   (+ 0.9 above the payload)
//
// off: the grasp's distance from the sherd's centre as a fraction of half its length (clamped
// at 1); along: |cos| of the angle between the fingers' closing direction and the outline's own
// major axis; elongation: 1 - width / length of the outline along that axis.
#include <Eigen/Core>

#include "rascal_sim/SherdMeshBuilder.hpp"

namespace rascal_sim {

struct SlipModel {
  /// 1 - width / length of `axes` (0 for a round outline, or none).
  static double elongation(const OutlineAxes& axes);
  /// |cos| between `closing` (in the sherd's frame; its xy part is used) and the major axis.
  static double closingAlong(const Eigen::Vector3d& closing, const OutlineAxes& axes);
  /// The term of closing along the long axis: a sherd as wide as it is long has no long axis to
  /// close along (turned 90 degrees it is the same grasp), so it grows with the elongation, in
  /// full from W/L = 0.6.
  static double alongTerm(double along, double elongation);
  /// The chance, at most 0.98; `overweight` adds 0.9 (above the arm's working payload).
  static double chance(double off_centre, double along, double elongation, bool overweight);
};

}  // namespace rascal_sim
