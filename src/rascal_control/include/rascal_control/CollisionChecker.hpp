// Collision checking of arm states and planned paths against the table and the station fixtures,
// with FCL. The arm's bodies are the URDF's <collision> boxes and cylinders of every link that
// moves; fixtures are axis-aligned boxes standing on the table.
#pragma once

#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <fcl/narrowphase/collision_object.h>
#include <kdl/frames.hpp>

#include "rascal_control/JointPath.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_workcell/Workcell.hpp"

namespace rascal_control {

struct Fixture {
  std::string name;
  KDL::Vector centre;  // [m] box centre in base_link
  KDL::Vector size;    // [m] along x, y, z
  // A support surface (the table, the scale platform): the fingertips may touch it, because
  // picking and placing flat sherds needs them there; every other arm body may not.
  bool support = false;
  // Arm links allowed to touch it (the arm's own base: the links mounted on it).
  std::set<std::string> allowed;
  double yaw = 0.0;    // [rad] about +z: the box turns with its station
};

class CollisionChecker {
 public:
  struct Hit {
    std::string link;
    std::string fixture;
    double s = 0.0;  // where along the path, 0..1
    JointVector q{};
  };

  // `finger` [m]: finger position assumed for the fingers' bodies (default: the URDF's upper limit
  // of left_finger, fully open, widest).
  // The arm's own base (base_link's collision boxes) is a fixture from the start: every link but
  // shoulder_link and upper_arm_link must keep off it.
  explicit CollisionChecker(const KinematicModel& model, std::optional<double> finger = std::nullopt);

  void addFixture(const Fixture& fixture);
  // The workcell's fixtures (rascal_workcell::Workcell::collisionBoxes()); a support box (the
  // scale platform) may be touched by the fingertips.
  void addFixtures(const std::vector<rascal_workcell::FixtureBox>& boxes);
  // The table top z = 0 (on by default).
  void setTable(bool enabled) { table_ = enabled; }
  const std::vector<Fixture>& fixtures() const { return fixtures_; }
  // Names of the arm links whose bodies are checked.
  std::vector<std::string> checkedLinks() const;

  // The first arm body touching a fixture at `q`, if any. Not thread-safe.
  std::optional<Hit> check(const JointVector& q) const;
  // The first contact along a path, sampled so that no joint moves more than `max_step` [rad]
  // between samples. Contacts that already exist at the start are ignored (so the arm can always
  // move away from one).
  std::optional<Hit> check(const JointPath& path, double max_step = 0.01) const;

 private:
  struct Body {
    std::string link;
    int chain_index;
    KDL::Frame offset;  // chain frame -> shape centre
    bool finger;
    std::shared_ptr<fcl::CollisionObjectd> object;
  };
  using Pair = std::pair<std::size_t, std::size_t>;  // body, fixture (fixtures_.size() = table)

  void contacts(const JointVector& q, std::vector<Pair>& out, const std::set<Pair>* ignore,
                bool first_only) const;

  const KinematicModel& model_;
  std::vector<Body> bodies_;
  std::vector<Fixture> fixtures_;
  std::vector<std::shared_ptr<fcl::CollisionObjectd>> fixture_objects_;
  std::shared_ptr<fcl::CollisionObjectd> table_object_;
  bool table_ = true;
};

}  // namespace rascal_control
