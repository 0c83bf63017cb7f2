// Shared helpers of the core tests: the URDF from the source tree and random joint vectors.
#pragma once

#include <random>

#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

inline const KinematicModel& testModel() {
  static const KinematicModel model = KinematicModel::fromFile(RASCAL_URDF_PATH);
  return model;
}

inline JointVector randomJoints(std::mt19937& rng, const KinematicModel& model, double margin = 0.0) {
  JointVector q{};
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    std::uniform_real_distribution<double> u(model.limits()[j].lower + margin,
                                             model.limits()[j].upper - margin);
    q[j] = u(rng);
  }
  return q;
}

}  // namespace rascal_control
