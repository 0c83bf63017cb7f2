#include "rascal_control/CollisionChecker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/halfspace.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>

namespace rascal_control {

namespace {

fcl::Transform3d toFcl(const KDL::Frame& f) {
  fcl::Transform3d t = fcl::Transform3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      t.linear()(i, j) = f.M(i, j);
    }
    t.translation()(i) = f.p(i);
  }
  return t;
}

bool isFinger(const std::string& link) {
  return link == "left_finger_link" || link == "right_finger_link";
}

}  // namespace

CollisionChecker::CollisionChecker(const KinematicModel& model, std::optional<double> finger_position)
    : model_(model) {
  double lower = 0.0, finger = 0.0;
  if (finger_position) {
    finger = *finger_position;
  } else if (!model_.jointLimits("left_finger", lower, finger)) {
    throw std::runtime_error("CollisionChecker: the URDF has no left_finger joint with limits");
  }
  const KDL::Tree& tree = model_.tree();
  std::vector<Fixture> base;
  for (const CollisionShape& shape : model_.collisionShapes()) {
    // The nearest ancestor on the arm chain carries this link.
    std::string ancestor = shape.link;
    while (model_.chainIndex(ancestor) < 0) {
      const auto it = tree.getSegments().find(ancestor);
      if (it == tree.getSegments().end() || ancestor == tree.getRootSegment()->first) {
        ancestor.clear();
        break;
      }
      ancestor = GetTreeElementParent(it->second)->first;
    }
    if (ancestor.empty()) {
      // Does not move with the arm (base_link): an obstacle for the links further out.
      const KDL::Frame centre = shape.origin;
      double roll = 0.0, pitch = 0.0, yaw = 0.0;
      centre.M.GetRPY(roll, pitch, yaw);
      if (shape.type == CollisionShape::Type::Box && std::fabs(roll) + std::fabs(pitch) + std::fabs(yaw) < 1e-9) {
        base.push_back({"arm base", centre.p, shape.size, false, {"shoulder_link", "upper_arm_link"}});
      }
      continue;
    }
    KDL::Chain sub;
    KDL::Frame offset = KDL::Frame::Identity();
    if (ancestor != shape.link) {
      if (!tree.getChain(ancestor, shape.link, sub)) {
        throw std::runtime_error("CollisionChecker: no chain " + ancestor + " -> " + shape.link);
      }
      for (const KDL::Segment& segment : sub.segments) {
        const std::string& joint = segment.getJoint().getName();
        const double value = joint == "left_finger" ? finger : joint == "right_finger" ? -finger : 0.0;
        offset = offset * segment.pose(segment.getJoint().getType() == KDL::Joint::None ? 0.0 : value);
      }
    }
    std::shared_ptr<fcl::CollisionGeometryd> geometry;
    switch (shape.type) {
      case CollisionShape::Type::Box:
        geometry = std::make_shared<fcl::Boxd>(shape.size.x(), shape.size.y(), shape.size.z());
        break;
      case CollisionShape::Type::Cylinder:
        geometry = std::make_shared<fcl::Cylinderd>(shape.size.x(), shape.size.y());
        break;
      case CollisionShape::Type::Sphere:
        geometry = std::make_shared<fcl::Sphered>(shape.size.x());
        break;
    }
    bodies_.push_back({shape.link, model_.chainIndex(ancestor), offset * shape.origin,
                       isFinger(shape.link), std::make_shared<fcl::CollisionObjectd>(geometry)});
  }
  for (const Fixture& f : base) {
    addFixture(f);
  }
  table_object_ = std::make_shared<fcl::CollisionObjectd>(
      std::make_shared<fcl::Halfspaced>(fcl::Vector3d(0.0, 0.0, 1.0), 0.0));
}

std::vector<std::string> CollisionChecker::checkedLinks() const {
  std::vector<std::string> links;
  for (const Body& body : bodies_) {
    if (std::find(links.begin(), links.end(), body.link) == links.end()) {
      links.push_back(body.link);
    }
  }
  return links;
}

void CollisionChecker::addFixture(const Fixture& fixture) {
  if (!(fixture.size.x() > 0.0 && fixture.size.y() > 0.0 && fixture.size.z() > 0.0)) {
    throw std::invalid_argument("CollisionChecker::addFixture: '" + fixture.name +
                                "' needs a positive size");
  }
  fixtures_.push_back(fixture);
  auto object = std::make_shared<fcl::CollisionObjectd>(
      std::make_shared<fcl::Boxd>(fixture.size.x(), fixture.size.y(), fixture.size.z()));
  object->setTransform(toFcl(KDL::Frame(KDL::Rotation::RotZ(fixture.yaw), fixture.centre)));
  object->computeAABB();
  fixture_objects_.push_back(object);
}

void CollisionChecker::addFixtures(const std::vector<rascal_workcell::FixtureBox>& boxes) {
  for (const rascal_workcell::FixtureBox& b : boxes) {
    addFixture({b.name, KDL::Vector(b.centre.x(), b.centre.y(), b.centre.z()),
                KDL::Vector(b.size.x(), b.size.y(), b.size.z()), b.is_support, {}, b.yaw});
  }
}

void CollisionChecker::contacts(const JointVector& q, std::vector<Pair>& out,
                                const std::set<Pair>* ignore, bool first_only) const {
  const std::vector<KDL::Frame> frames = model_.chainFrames(q);
  fcl::CollisionRequestd request;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const Body& body = bodies_[b];
    body.object->setTransform(toFcl(frames[body.chain_index] * body.offset));
    body.object->computeAABB();
    const fcl::AABBd& box = body.object->getAABB();
    for (std::size_t f = 0; f <= fixtures_.size(); ++f) {
      const bool table = f == fixtures_.size();
      if (table ? !table_ : false) {
        continue;
      }
      if (body.finger && (table || fixtures_[f].support)) {
        continue;
      }
      if (!table && fixtures_[f].allowed.count(body.link)) {
        continue;
      }
      if (ignore && ignore->count({b, f})) {
        continue;
      }
      if (table ? box.min_[2] > 0.0 : !box.overlap(fixture_objects_[f]->getAABB())) {
        continue;
      }
      fcl::CollisionResultd result;
      fcl::collide(body.object.get(), table ? table_object_.get() : fixture_objects_[f].get(),
                   request, result);
      if (result.isCollision()) {
        out.push_back({b, f});
        if (first_only) {
          return;
        }
      }
    }
  }
}

std::optional<CollisionChecker::Hit> CollisionChecker::check(const JointVector& q) const {
  std::vector<Pair> found;
  contacts(q, found, nullptr, true);
  if (found.empty()) {
    return std::nullopt;
  }
  const Pair& p = found.front();
  return Hit{bodies_[p.first].link,
             p.second == fixtures_.size() ? std::string("table") : fixtures_[p.second].name, 0.0, q};
}

std::optional<CollisionChecker::Hit> CollisionChecker::check(const JointPath& path,
                                                             double max_step) const {
  if (!(max_step > 0.0)) {
    throw std::invalid_argument("CollisionChecker::check: max_step must be positive");
  }
  // How finely to sample: the largest joint change between coarse samples.
  constexpr int kCoarse = 64;
  double largest = 0.0;
  JointVector previous = path.at(0.0);
  for (int k = 1; k <= kCoarse; ++k) {
    const JointVector q = path.at(static_cast<double>(k) / kCoarse);
    for (std::size_t j = 0; j < kArmJoints; ++j) {
      largest = std::max(largest, std::fabs(q[j] - previous[j]));
    }
    previous = q;
  }
  const int samples = std::max(1, static_cast<int>(std::ceil(largest / max_step * 1.5)) * kCoarse);
  std::vector<Pair> at_start;
  contacts(path.at(0.0), at_start, nullptr, false);
  const std::set<Pair> ignore(at_start.begin(), at_start.end());
  for (int k = 1; k <= samples; ++k) {
    const double s = static_cast<double>(k) / samples;
    const JointVector q = path.at(s);
    std::vector<Pair> found;
    contacts(q, found, &ignore, true);
    if (!found.empty()) {
      const Pair& p = found.front();
      return Hit{bodies_[p.first].link,
                 p.second == fixtures_.size() ? std::string("table") : fixtures_[p.second].name, s, q};
    }
  }
  return std::nullopt;
}

}  // namespace rascal_control
