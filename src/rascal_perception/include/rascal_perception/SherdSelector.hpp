#pragma once
// Orders detected sherds by the selection policy: nearest first (to a reference point, normally
// the camera's footprint, i.e. where the gripper already is), largest (top-view area) first, or
// most isolated (largest gap to a neighbour) first. Ties keep image order.
#include <Eigen/Core>
#include <vector>

#include "rascal_perception/Types.hpp"

namespace rascal_perception {

class SherdSelector {
 public:
  static void order(std::vector<SherdDetection>& sherds, SelectionPolicy policy, const Eigen::Vector2d& reference);
};

}  // namespace rascal_perception
