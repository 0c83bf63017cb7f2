// Closed-form inverse kinematics of a wx250s-type arm: waist about z, shoulder and elbow about y,
// and a spherical wrist (forearm_roll x, wrist_angle y, wrist_rotate x) whose axes meet in one
// point. The geometry is read from the KDL chain, so it follows the URDF.
#pragma once

#include <string>
#include <vector>

#include <kdl/chain.hpp>
#include <kdl/frames.hpp>

#include "rascal_control/KinematicModel.hpp"

namespace rascal_control {

class AnalyticIk {
 public:
  // Arm geometry at q = 0, in base_link. All points lie in the plane y = 0.
  struct Geometry {
    KDL::Vector shoulder;   // a point of the shoulder axis
    KDL::Vector elbow;      // a point of the elbow axis
    KDL::Vector wrist;      // where the three wrist axes meet
    KDL::Frame tip_home;    // ee_gripper_link at q = 0
  };

  // Reads the geometry from a base_link -> tip chain; false (with `why`) if the chain is not of
  // this type (other axes, offsets out of the plane, wrist axes that do not meet).
  static bool extract(const KDL::Chain& chain, Geometry& geometry, std::string& why);

  explicit AnalyticIk(const Geometry& geometry);

  // Every solution for `target` (up to 8, angles in (-pi, pi]); singular joints (waist over the
  // shoulder, wrist_angle = 0) take their value from `seed`. Returns false when the wrist centre
  // is out of reach; `reach_error` then says by how much [m].
  bool solveAll(const KDL::Frame& target, const JointVector& seed, std::vector<JointVector>& out,
                double& reach_error) const;

  const Geometry& geometry() const { return geometry_; }
  // [m] largest and smallest shoulder-axis -> wrist-centre distance.
  double maxReach() const;
  double minReach() const;

 private:
  Geometry geometry_;
  KDL::Vector tip_offset_;  // wrist centre -> tip in the gripper frame at q = 0
  double l1r_, l1z_, l2r_, l2z_;  // shoulder -> elbow and elbow -> wrist in the arm plane (r, z)
};

}  // namespace rascal_control
