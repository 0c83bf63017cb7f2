#include "rascal_workcell/GripperGeometry.hpp"

#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rascal_workcell {

namespace {
constexpr const char* kFingerJoint = "left_finger";
constexpr const char* kFingerLink = "left_finger_link";
constexpr const char* kTipJoint = "ee_gripper";  // fingers_link -> ee_gripper_link
}  // namespace

GripperGeometry GripperGeometry::fromUrdf(const std::string& urdf_xml) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(urdf_xml);
  if (!model) throw std::invalid_argument("URDF: cannot be parsed");
  const auto joint = model->getJoint(kFingerJoint);
  if (!joint || !joint->limits) {
    throw std::invalid_argument(std::string("URDF: no joint ") + kFingerJoint + " with limits");
  }
  GripperGeometry g;
  g.finger_min = joint->limits->lower;
  g.finger_max = joint->limits->upper;
  if (!(g.finger_min > 0.0 && g.finger_max > g.finger_min)) {
    throw std::invalid_argument(std::string("URDF: ") + kFingerJoint + " limits are not 0 < lower < upper");
  }
  // Fingertips: the far end of the finger's collision box along the approach axis (x of
  // fingers_link), measured from ee_gripper_link.
  const auto link = model->getLink(kFingerLink);
  const auto tip = model->getJoint(kTipJoint);
  if (!link || !link->collision || !link->collision->geometry ||
      link->collision->geometry->type != urdf::Geometry::BOX || !tip) {
    throw std::invalid_argument(std::string("URDF: ") + kFingerLink + " needs a box collision and joint " +
                                kTipJoint + " must exist");
  }
  const auto& box = static_cast<const urdf::Box&>(*link->collision->geometry);
  const double end = link->collision->origin.position.x + box.dim.x / 2.0;
  g.fingertip_offset = end - tip->parent_to_joint_origin_transform.position.x;
  return g;
}

GripperGeometry GripperGeometry::withPads(double p) const {
  if (!(p >= 0.0 && p < finger_min)) {
    throw std::invalid_argument("arm.gripper.fingertip_pads: " + std::to_string(p) +
                                " m; give each pad's thickness, 0 <= pads < " + std::to_string(finger_min) +
                                " m (at that the pads meet before the fingers close)");
  }
  GripperGeometry g = *this;
  g.pad = p;
  return g;
}

std::string GripperGeometry::packageUrdfPath() { return RASCAL_URDF_PATH; }

GripperGeometry GripperGeometry::fromPackageUrdf() {
  std::ifstream in(packageUrdfPath());
  if (!in) throw std::invalid_argument("URDF: cannot read " + packageUrdfPath());
  std::stringstream ss;
  ss << in.rdbuf();
  return fromUrdf(ss.str());
}

}  // namespace rascal_workcell
