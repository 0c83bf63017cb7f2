#include "rascal_workcell/GripperGeometry.hpp"

#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <deque>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

namespace rascal_workcell {

namespace {
constexpr const char* kFingerJoint = "left_finger";
constexpr const char* kFingerLink = "left_finger_link";
constexpr const char* kTipJoint = "ee_gripper";  // fingers_link -> ee_gripper_link
constexpr const char* kTipLink = "ee_gripper_link";

/// p_ee = r * p_link + t
struct ToEe {
  urdf::Rotation r;
  urdf::Vector3 t;
  urdf::Vector3 operator()(const urdf::Vector3& p) const { return r * p + t; }
};

urdf::Vector3 plus(const urdf::Vector3& a, const urdf::Vector3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }

/// The box collisions of every link joined to ee_gripper_link by fixed joints, as bounds in its
/// frame: walked from it up and down the tree across fixed joints only (the fingers' prismatic
/// joints and the wrist's revolute one end the walk).
std::vector<HandBox> handBoxes(const urdf::ModelInterface& model) {
  std::vector<HandBox> boxes;
  std::deque<std::pair<urdf::LinkConstSharedPtr, ToEe>> todo{{model.getLink(kTipLink), ToEe{}}};
  std::set<std::string> seen;
  while (!todo.empty()) {
    const auto [link, to] = todo.front();
    todo.pop_front();
    if (!link || !seen.insert(link->name).second) continue;
    for (const urdf::CollisionSharedPtr& c : link->collision_array) {
      if (!c || !c->geometry || c->geometry->type != urdf::Geometry::BOX) continue;
      const urdf::Vector3& d = static_cast<const urdf::Box&>(*c->geometry).dim;
      HandBox b;
      b.lo.fill(std::numeric_limits<double>::infinity());
      b.hi.fill(-std::numeric_limits<double>::infinity());
      for (int k = 0; k < 8; ++k) {
        const urdf::Vector3 corner(k & 1 ? d.x / 2 : -d.x / 2, k & 2 ? d.y / 2 : -d.y / 2, k & 4 ? d.z / 2 : -d.z / 2);
        const urdf::Vector3 q = to(plus(c->origin.rotation * corner, c->origin.position));
        const double v[3] = {q.x, q.y, q.z};
        for (int i = 0; i < 3; ++i) b.lo[i] = std::min(b.lo[i], v[i]), b.hi[i] = std::max(b.hi[i], v[i]);
      }
      boxes.push_back(b);
    }
    const auto up = link->parent_joint;
    if (up && up->type == urdf::Joint::FIXED) {  // the joint inverted: p_link = R^-1 (p_parent - t)
      const urdf::Pose& j = up->parent_to_joint_origin_transform;
      const urdf::Rotation inv = j.rotation.GetInverse();
      ToEe parent{to.r * inv, urdf::Vector3()};
      const urdf::Vector3 back = parent.r * j.position;
      parent.t = urdf::Vector3(to.t.x - back.x, to.t.y - back.y, to.t.z - back.z);
      todo.emplace_back(model.getLink(up->parent_link_name), parent);
    }
    for (const urdf::JointSharedPtr& down : link->child_joints) {
      if (!down || down->type != urdf::Joint::FIXED) continue;
      const urdf::Pose& j = down->parent_to_joint_origin_transform;
      todo.emplace_back(model.getLink(down->child_link_name), ToEe{to.r * j.rotation, to(j.position)});
    }
  }
  return boxes;
}
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
  g.hand = handBoxes(*model);
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
