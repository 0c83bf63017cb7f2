#include "rascal_control/KinematicModel.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

namespace rascal_control {

const std::array<std::string, kArmJoints>& KinematicModel::armJointNames() {
  static const std::array<std::string, kArmJoints> names = {
      "waist", "shoulder", "elbow", "forearm_roll", "wrist_angle", "wrist_rotate"};
  return names;
}

KinematicModel KinematicModel::fromFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw std::runtime_error("KinematicModel::fromFile: cannot read URDF file '" + path + "'");
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  KinematicModel model;
  model.build(buffer.str());
  return model;
}

KinematicModel KinematicModel::fromString(const std::string& urdf_xml) {
  KinematicModel model;
  model.build(urdf_xml);
  return model;
}

void KinematicModel::build(const std::string& urdf_xml) {
  const urdf::ModelInterfaceSharedPtr urdf_model = urdf::parseURDF(urdf_xml);
  if (!urdf_model) {
    throw std::runtime_error("KinematicModel: the URDF does not parse");
  }
  if (!kdl_parser::treeFromUrdfModel(*urdf_model, tree_)) {
    throw std::runtime_error("KinematicModel: kdl_parser cannot build a tree from the URDF");
  }
  if (!tree_.getChain(kBaseLink, kTipLink, chain_)) {
    throw std::runtime_error(std::string("KinematicModel: the URDF has no chain ") + kBaseLink +
                             " -> " + kTipLink);
  }
  // The chain's moving joints must be exactly the six arm joints, in order.
  std::size_t j = 0;
  for (const KDL::Segment& segment : chain_.segments) {
    if (segment.getJoint().getType() == KDL::Joint::None) {
      continue;
    }
    if (j >= kArmJoints || segment.getJoint().getName() != armJointNames()[j]) {
      throw std::runtime_error("KinematicModel: unexpected moving joint '" +
                               segment.getJoint().getName() + "' in the " + kBaseLink + " -> " +
                               kTipLink + " chain (expected " +
                               (j < kArmJoints ? armJointNames()[j] : std::string("none")) + ")");
    }
    ++j;
  }
  if (j != kArmJoints) {
    throw std::runtime_error("KinematicModel: the arm chain has " + std::to_string(j) +
                             " moving joints, expected 6");
  }
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    const urdf::JointConstSharedPtr joint = urdf_model->getJoint(armJointNames()[i]);
    if (!joint || !joint->limits || joint->type != urdf::Joint::REVOLUTE) {
      throw std::runtime_error("KinematicModel: joint '" + armJointNames()[i] +
                               "' must be revolute with <limit>");
    }
    limits_[i] = {joint->limits->lower, joint->limits->upper, joint->limits->velocity};
    if (!(limits_[i].lower < limits_[i].upper) || !(limits_[i].velocity > 0.0)) {
      throw std::runtime_error("KinematicModel: joint '" + armJointNames()[i] +
                               "' has empty limits or no velocity limit");
    }
  }
  for (const auto& entry : urdf_model->joints_) {
    const urdf::Joint& joint = *entry.second;
    if (joint.type == urdf::Joint::FIXED) {
      continue;
    }
    if (joint.limits && joint.type != urdf::Joint::CONTINUOUS) {
      all_limits_[joint.name] = {joint.limits->lower, joint.limits->upper};
    } else {
      all_limits_[joint.name] = {-M_PI, M_PI};
    }
  }
  for (const auto& entry : urdf_model->links_) {
    for (const urdf::CollisionSharedPtr& collision : entry.second->collision_array) {
      if (!collision || !collision->geometry) {
        continue;
      }
      CollisionShape shape;
      shape.link = entry.first;
      const urdf::Pose& o = collision->origin;
      shape.origin = KDL::Frame(KDL::Rotation::Quaternion(o.rotation.x, o.rotation.y, o.rotation.z,
                                                          o.rotation.w),
                                KDL::Vector(o.position.x, o.position.y, o.position.z));
      const urdf::Geometry& g = *collision->geometry;
      if (g.type == urdf::Geometry::BOX) {
        const auto& box = static_cast<const urdf::Box&>(g);
        shape.type = CollisionShape::Type::Box;
        shape.size = KDL::Vector(box.dim.x, box.dim.y, box.dim.z);
      } else if (g.type == urdf::Geometry::CYLINDER) {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(g);
        shape.type = CollisionShape::Type::Cylinder;
        shape.size = KDL::Vector(cylinder.radius, cylinder.length, 0.0);
      } else if (g.type == urdf::Geometry::SPHERE) {
        shape.type = CollisionShape::Type::Sphere;
        shape.size = KDL::Vector(static_cast<const urdf::Sphere&>(g).radius, 0.0, 0.0);
      } else {
        continue;
      }
      collision_shapes_.push_back(shape);
    }
  }
  has_camera_ = tree_.getChain(kBaseLink, kCameraLink, camera_chain_) &&
                camera_chain_.getNrOfJoints() == kArmJoints;
}

bool KinematicModel::jointLimits(const std::string& joint, double& lower, double& upper) const {
  const auto it = all_limits_.find(joint);
  if (it == all_limits_.end()) {
    return false;
  }
  lower = it->second.first;
  upper = it->second.second;
  return true;
}

int KinematicModel::firstLimitViolation(const JointVector& q, double tolerance) const {
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    if (!(q[i] >= limits_[i].lower - tolerance && q[i] <= limits_[i].upper + tolerance)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

bool KinematicModel::withinLimits(const JointVector& q, double tolerance) const {
  return firstLimitViolation(q, tolerance) < 0;
}

namespace {

KDL::Frame chainPose(const KDL::Chain& chain, const JointVector& q) {
  KDL::Frame pose = KDL::Frame::Identity();
  std::size_t j = 0;
  for (const KDL::Segment& segment : chain.segments) {
    if (segment.getJoint().getType() == KDL::Joint::None) {
      pose = pose * segment.pose(0.0);
    } else {
      pose = pose * segment.pose(q[j++]);
    }
  }
  return pose;
}

}  // namespace

KDL::Frame KinematicModel::forward(const JointVector& q) const { return chainPose(chain_, q); }

KDL::Frame KinematicModel::cameraOptical(const JointVector& q) const {
  if (!has_camera_) {
    throw std::logic_error(std::string("KinematicModel::cameraOptical: the URDF has no ") +
                           kCameraLink + " on the arm");
  }
  return chainPose(camera_chain_, q);
}

std::vector<KDL::Frame> KinematicModel::chainFrames(const JointVector& q) const {
  std::vector<KDL::Frame> frames;
  frames.reserve(chain_.getNrOfSegments());
  KDL::Frame pose = KDL::Frame::Identity();
  std::size_t j = 0;
  for (const KDL::Segment& segment : chain_.segments) {
    const bool moving = segment.getJoint().getType() != KDL::Joint::None;
    pose = pose * segment.pose(moving ? q[j++] : 0.0);
    frames.push_back(pose);
  }
  return frames;
}

int KinematicModel::chainIndex(const std::string& link) const {
  for (std::size_t i = 0; i < chain_.segments.size(); ++i) {
    if (chain_.segments[i].getName() == link) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

bool KinematicModel::linkPose(const std::string& link, const JointVector& q, double finger,
                              KDL::Frame& pose) const {
  if (link == kBaseLink) {
    pose = KDL::Frame::Identity();
    return true;
  }
  KDL::Chain chain;
  if (tree_.getSegments().count(link) == 0 || !tree_.getChain(kBaseLink, link, chain)) {
    return false;
  }
  std::map<std::string, double> positions;
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    positions[armJointNames()[i]] = q[i];
  }
  positions["left_finger"] = finger;
  positions["right_finger"] = -finger;
  pose = KDL::Frame::Identity();
  for (const KDL::Segment& segment : chain.segments) {
    const auto it = positions.find(segment.getJoint().getName());
    const bool moving = segment.getJoint().getType() != KDL::Joint::None;
    pose = pose * segment.pose(moving && it != positions.end() ? it->second : 0.0);
  }
  return true;
}

std::vector<LinkTransform> KinematicModel::transforms(const std::map<std::string, double>& positions,
                                                      bool fixed) const {
  std::vector<LinkTransform> out;
  for (const auto& entry : tree_.getSegments()) {
    const KDL::Segment& segment = GetTreeElementSegment(entry.second);
    if (entry.first == tree_.getRootSegment()->first) {
      continue;
    }
    const bool moving = segment.getJoint().getType() != KDL::Joint::None;
    if (moving == fixed) {
      continue;
    }
    double value = 0.0;
    if (moving) {
      const auto it = positions.find(segment.getJoint().getName());
      if (it != positions.end()) {
        value = it->second;
      } else {
        const auto limit = all_limits_.find(segment.getJoint().getName());
        if (limit != all_limits_.end() && (limit->second.first > 0.0 || limit->second.second < 0.0)) {
          value = limit->second.first;
        }
      }
    }
    out.push_back({GetTreeElementParent(entry.second)->first, entry.first, segment.pose(value)});
  }
  return out;
}

}  // namespace rascal_control
