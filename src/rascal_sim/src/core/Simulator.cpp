#include "rascal_sim/Simulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "rascal_sim/SherdMeshBuilder.hpp"
#include "rascal_sim/SlipModel.hpp"

namespace rascal_sim {

namespace {
constexpr double kExposure = 0.01;  // [s] wrist colour exposure used for the blur length

const SimulatorOptions& checked(const SimulatorOptions& o) {
  const auto& g = o.gripper;
  if (!(g.finger_min > 0.0 && g.finger_max > g.finger_min)) {
    throw std::invalid_argument(
        "Simulator: SimulatorOptions::gripper has no finger limits; fill it from "
        "rascal_workcell::GripperGeometry::fromPackageUrdf() (SimParameters::read does)");
  }
  if (!(o.initial_finger >= g.finger_min && o.initial_finger <= g.finger_max)) {
    throw std::invalid_argument("Simulator: SimulatorOptions::initial_finger " + std::to_string(o.initial_finger) +
                                " m is outside the finger limits [" + std::to_string(g.finger_min) + ", " +
                                std::to_string(g.finger_max) + "] m");
  }
  return o;
}
}  // namespace

Simulator::Simulator(const WorldLayout& layout, const SimulatorOptions& options)
    : layout_(layout),
      options_(checked(options)),
      world_(std::make_unique<World>(layout, options.gripper)),
      servos_(options.initial_joints),
      gripper_(options.gripper, options.initial_finger),
      scale_(7),
      archival_(layout, options.archival_width, options.archival_height),
      effects_(kSensorSeed),
      rng_(1) {
  world_->placeArm(servos_.positions(), gripper_.position());
}

void Simulator::load(const Scenario& scenario) {
  if (scenario.station_offsets != scenario_.station_offsets) moveStations(scenario.station_offsets);
  if (scenario.lighting.realism.any() && !realism_.loaded()) realism_.load(layout_.data_dir);
  world_->spawn(scenario.sherds);
  world_->seedSolver(scenario.seed);
  scenario_ = scenario;
  rng_.seed(scenario.seed);
  // the frames of a scenario do not depend on what was rendered before it was loaded (tests
  // render many scenes in one simulator, in any order)
  effects_.reseed(kSensorSeed);
  slip_armed_ = false;
  close_armed_ = false;
  open_requested_ = false;
  last_touch_.clear();
  bumps_.clear();
}

void Simulator::moveStations(const std::map<std::string, StationOffset>& offsets) {
  if (archival_.state() != ArchivalCamera::State::kIdle) {
    throw std::runtime_error("station_offsets: the stations cannot move during an archival capture");
  }
  WorldLayout moved = layout_;  // the configured layout: offsets never add up
  for (const auto& [name, o] : offsets) moved.offsetStation(name, o.dx, o.dy, o.dyaw);
  // ODE's static geoms and the fixture mesh are built once: a new world, on the same clock
  world_ = std::make_unique<World>(moved, options_.gripper, time());
  world_->placeArm(servos_.positions(), gripper_.position());
  archival_ = ArchivalCamera(moved, options_.archival_width, options_.archival_height);
}

void Simulator::reset() {
  world_->release();
  world_->spawn(scenario_.sherds);
  servos_.reset(options_.initial_joints);
  gripper_.reset(options_.initial_finger);
  world_->placeArm(servos_.positions(), gripper_.position());
  world_->seedSolver(scenario_.seed);
  rng_.seed(scenario_.seed);
  slip_armed_ = false;
  drop_next_grasp_ = false;
  scale_.clearFaults();
  close_armed_ = false;
  open_requested_ = false;
  last_touch_.clear();
  bumps_.clear();
}

void Simulator::commandArm(double start_time, const std::vector<TrajectoryPoint>& points,
                           const std::array<bool, kArmJoints>& mask) {
  servos_.setTrajectory(time(), start_time, points, mask);
}

void Simulator::commandGripper(double finger_position) {
  const double previous = gripper_.target(), q = gripper_.position();
  const bool squeezed = squeezing();
  gripper_.setTarget(finger_position);
  const double target = gripper_.target();
  if (target < previous - 1e-6 && target < q - 1e-6) {
    close_armed_ = true;
    close_left_ = close_right_ = -1;
    close_recorded_ = false;
    world_->stopIgnoringOverlaps();
  } else if (target > previous + kReleaseStep && std::abs(target - q) > 1e-4) {
    // an open, even to less than where a sherd wedged the fingers (not a stop where they are)
    close_armed_ = false;
    open_requested_ = true;
  } else if (target >= gripper_.fingerMax() - 1e-6) {
    close_armed_ = false;
    open_requested_ = true;
  } else if (target > previous && squeezed) {
    gripper_.setTarget(previous);  // a stop where a squeezed sherd holds the fingers: keeps squeezing
  }
}

void Simulator::stopGripper() {
  if (!squeezing()) gripper_.setTarget(gripper_.position());
}

bool Simulator::squeezing() const {
  // PWM mode: the servo keeps its closing effort on an object between the fingers, so a stop
  // there does not end the close; when the object goes, the fingers go on to the close target
  if (!close_armed_ || !gripper_.closing()) return false;
  const FingerContacts& fc = world_->fingerContacts();
  return world_->held() >= 0 || (fc.left >= 0 && fc.left == fc.right);
}

void Simulator::step() {
  const double dt = options_.physics_dt;
  const double now = time();
  servos_.step(now, dt);
  const FingerContacts& fc = world_->fingerContacts();
  const bool squeezed = fc.left >= 0 && fc.left == fc.right;
  const bool blocked = world_->held() >= 0 || squeezed || fc.left_depth > 0.002 || fc.right_depth > 0.002;
  gripper_.step(dt, blocked);
  world_->setArmTarget(servos_.positions(), gripper_.position());
  world_->step(dt);
  recordBumps();
  updateGrasp();
  if (scale_.update(time(), dt, world_->scaleLoad())) scale_fresh_ = true;
  if (archival_.update(time(), world_->armPose())) archival_.deliver(time(), renderArchival(capture_exposure_ev_));
}

void Simulator::releaseByOpening() {
  const int held = world_->held();
  world_->release();
  // a sherd whose box is wedged between the fingers (grasped across its corners) would stay
  // stuck there by contact friction: it passes through the arm until it is clear of it
  world_->ignoreGripperContactsWhileOverlapping(held);
  slip_armed_ = false;
  close_armed_ = false;
  open_requested_ = false;
}

void Simulator::updateGrasp() {
  const int held = world_->held();
  if (held >= 0) {
    // the fixed joint holds only while the fingers press on the sherd: any open lets it go,
    // and it never stays attached to fingers commanded fully open
    if (open_requested_ || gripper_.opening() || gripper_.target() >= gripper_.fingerMax() - 1e-6) {
      releaseByOpening();
      return;
    }
    if (slip_armed_) {
      const double z = world_->sherd(held).pose.translation().z();
      if (z > grasp_z_ + 0.01) {
        if (slip_lifted_since_ < 0) slip_lifted_since_ = time();
        if (time() - slip_lifted_since_ >= slip_delay_) {
          world_->release();
          world_->ignoreGripperContacts(held, time() + 0.6);
          slip_armed_ = false;
        }
      }
    }
    return;
  }
  open_requested_ = false;
  const FingerContacts& fc = world_->fingerContacts();
  if (close_armed_ && !close_recorded_) {
    if (fc.left >= 0) close_left_ = fc.left;
    if (fc.right >= 0) close_right_ = fc.right;
    if (!gripper_.closing()) recordMiss();
  }
  // only a close commanded since the last open grasps (an open to less than where a wedged
  // sherd held the fingers moves them inwards, but must not grasp it again)
  if (!close_armed_ || !gripper_.closing() || fc.left < 0 || fc.left != fc.right) return;
  const int i = fc.left;
  world_->hold(i);
  const SherdState s = world_->sherd(i);
  grasp_z_ = s.pose.translation().z();
  // off-centre grasps, fingers closing along the long axis and payloads above the 0.25 kg
  // working payload slip more often (SlipModel: a simulator choice, not a measured figure)
  const auto& arm = world_->armPose();
  const Eigen::Vector3d c = s.pose.inverse() * arm[kEeGripperLink].translation();
  const double off = std::min(1.0, std::hypot(c.x(), c.y()) / std::max(1e-3, 0.5 * s.length));
  // along the outline's own major axis, as a person (and the detector) sees it
  const OutlineAxes axes = SherdMeshBuilder::principalAxes(s.outline);
  const double along = SlipModel::closingAlong(s.pose.linear().transpose() * arm[kFingersLink].linear().col(1), axes);
  const double elongation = SlipModel::elongation(axes);
  const double p = SlipModel::chance(off, along, elongation, s.mass > kMaxPayload);
  GraspRecord r;
  r.count = last_grasp_.count + 1;
  r.sherd = s.name;
  r.time = time();
  r.off_centre = off;
  r.along = along;
  r.elongation = elongation;
  r.slip_chance = p;
  last_grasp_ = r;
  close_recorded_ = true;
  const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng_);
  slip_armed_ = drop_next_grasp_ || u < p;
  drop_next_grasp_ = false;
  slip_delay_ = std::uniform_real_distribution<double>(0.05, 0.6)(rng_);
  slip_lifted_since_ = -1.0;
}

namespace {
/// Lowest and highest z of the corners of `s`'s box.
void boxHeights(const SherdState& s, double& low, double& high) {
  low = std::numeric_limits<double>::infinity();
  high = -low;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner(c & 1 ? 0.5 : -0.5, c & 2 ? 0.5 : -0.5, c & 4 ? 0.5 : -0.5);
    const double z = (s.pose * corner.cwiseProduct(s.box_size)).z();
    low = std::min(low, z);
    high = std::max(high, z);
  }
}
}  // namespace

void Simulator::recordBumps() {
  const bool closing = close_armed_ && gripper_.closing();  // touching what it closes on
  for (const ArmTouch& t : world_->armTouches()) {
    const auto last = last_touch_.find(t.sherd);
    const bool fresh = last == last_touch_.end() || time() - last->second > kBumpGap;
    last_touch_[t.sherd] = time();
    if (!fresh || closing) continue;
    const SherdState s = world_->sherd(static_cast<size_t>(t.sherd));
    BumpRecord r;
    r.time = time();
    r.sherd = s.name;
    r.link = ArmKinematics::linkName(static_cast<ArmLink>(t.link));
    const Eigen::Isometry3d& ee = world_->armPose()[kEeGripperLink];
    r.ee = ee.translation();
    r.contact = ee.inverse() * t.point;
    r.at = s.pose.translation().head<2>();
    boxHeights(s, r.low, r.high);
    if (bumps_.size() >= kMaxBumps) bumps_.erase(bumps_.begin());
    bumps_.push_back(r);
  }
}

std::vector<Simulator::BumpRecord> Simulator::takeBumps() {
  std::vector<BumpRecord> out;
  out.swap(bumps_);
  return out;
}

std::vector<std::string> Simulator::takeLogLines() {
  std::vector<std::string> lines;
  if (last_grasp_.count != grasps_logged_) {
    grasps_logged_ = last_grasp_.count;
    lines.push_back(last_grasp_.describe());
  }
  for (const BumpRecord& b : takeBumps()) lines.push_back(b.describe());
  return lines;
}

std::string Simulator::BumpRecord::describe() const {
  char line[320];
  std::snprintf(line, sizeof(line),
                "bump at t=%.2f s: %s on %s at (%.3f, %.3f) m, its box from z %.1f to %.1f mm; "
                "ee_gripper_link at (%.3f, %.3f, %.3f) m; touching at (%.1f, %.1f, %.1f) mm in its frame",
                time, link.c_str(), sherd.c_str(), at.x(), at.y(), low * 1000.0, high * 1000.0, ee.x(), ee.y(),
                ee.z(), contact.x() * 1000.0, contact.y() * 1000.0, contact.z() * 1000.0);
  return line;
}

void Simulator::recordMiss() {
  close_recorded_ = true;
  const Eigen::Vector3d ee = world_->armPose()[kEeGripperLink].translation();
  GraspRecord r;
  r.count = last_grasp_.count + 1;
  r.time = time();
  r.miss = true;
  r.finger = gripper_.position();
  r.ee_z = ee.z();
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < world_->sherdCount(); ++i) {
    const SherdState s = world_->sherd(i);
    const double d = (s.pose.translation() - ee).head<2>().norm();
    if (d < nearest) {
      nearest = d;
      r.sherd = s.name;
      r.off_centre = std::min(1.0, d / std::max(1e-3, 0.5 * s.length));
      boxHeights(s, r.low, r.high);
    }
  }
  const auto name = [this](int i) { return i >= 0 ? world_->sherd(static_cast<size_t>(i)).name : std::string(); };
  r.left = name(close_left_);
  r.right = name(close_right_);
  last_grasp_ = r;
}

std::string Simulator::GraspRecord::describe() const {
  char line[256];
  if (miss) {
    std::snprintf(line, sizeof(line),
                  "miss at t=%.2f s: fingers stopped at %.1f mm, left touched %s, right %s; nearest "
                  "sherd %s, %.2f of half its length off its centre, its box from z %.1f to %.1f mm; "
                  "ee_gripper_link at z %.1f mm",
                  time, finger * 1000.0, left.empty() ? "nothing" : left.c_str(),
                  right.empty() ? "nothing" : right.c_str(), sherd.c_str(), off_centre, low * 1000.0,
                  high * 1000.0, ee_z * 1000.0);
    return line;
  }
  std::snprintf(line, sizeof(line),
                "grasp of %s at t=%.2f s: %.2f of half its length off its centre, closing %.2f "
                "along its long axis (elongation %.2f): slip chance %.3f",
                sherd.c_str(), time, off_centre, along, elongation, slip_chance);
  return line;
}

bool Simulator::takeScaleReading(ScaleReading& reading) {
  if (!scale_fresh_) return false;
  scale_fresh_ = false;
  reading = scale_.latest();
  return true;
}

bool Simulator::wristFrameDue() const {
  return options_.wrist_camera && time() >= next_wrist_frame_ - 1e-9;
}

Eigen::Isometry3d Simulator::wristCameraPose() const {
  return world_->armPose()[kCameraColorOpticalFrame];
}

WristFrame Simulator::renderWristFrame() {
  WristFrame f;
  f.stamp = time();
  f.world_T_camera = wristCameraPose();
  world_->renderItems(items_, true);
  const CameraModel& cam = options_.wrist_model;
  renderer_.render(items_, cam, f.world_T_camera, scratch_, SensorEffects::lightGain(scenario_.lighting));
  const double speed = std::max(servos_.maxSpeed(), 0.0);
  double blur = 0.0;
  if (speed > kBlurSpeed) {
    f.blurred = true;
    blur = std::max(3.0, speed * cam.fx * kExposure);
  }
  realism_.apply(scratch_.colour, scratch_, cam, f.world_T_camera, scenario_.lighting.realism);
  effects_.colourImage(scratch_.colour, scratch_.depth, cam, f.world_T_camera, scenario_.lighting, f.stamp, blur);
  f.rgb = scratch_.colour.clone();
  f.depth_mm = effects_.depthImage(scratch_.depth, cam);
  skipWristFrame();
  return f;
}

void Simulator::skipWristFrame() {
  const double period = 1.0 / options_.wrist_rate;
  while (next_wrist_frame_ <= time() + 1e-9) next_wrist_frame_ += period;
}

cv::Mat Simulator::renderArchival(double exposure_ev) {
  world_->renderItems(items_, true);
  RenderOutput out;
  // exposure scales the light reaching the sensor, before its tone curve clips
  const Eigen::Vector3f gain = SensorEffects::lightGain(scenario_.lighting) * static_cast<float>(std::exp2(exposure_ev));
  renderer_.render(items_, archival_.model(), archival_.pose(), out, gain);
  effects_.colourImage(out.colour, out.depth, archival_.model(), archival_.pose(), scenario_.lighting, time(), 0.0);
  SensorEffects::archivalCamera(out.colour, archival_.model());
  return out.colour;
}

bool Simulator::triggerCapture(std::string& why, double exposure_ev) {
  if (!(std::abs(exposure_ev) <= kMaxExposureEv)) {
    why = "exposure_ev " + std::to_string(exposure_ev) + " outside -3..3 EV";
    return false;
  }
  capture_exposure_ev_ = exposure_ev;
  return archival_.trigger(time(), time() < camera_fault_until_, camera_fault_until_, why);
}

bool Simulator::injectFault(int fault, double duration, std::string& message) {
  switch (fault) {
    case static_cast<int>(Fault::kDropNextGrasp):
      drop_next_grasp_ = true;
      message = "the next grasped sherd slips out after lift";
      return true;
    case static_cast<int>(Fault::kScaleGlitch):
    case static_cast<int>(Fault::kCameraTimeout):
    case static_cast<int>(Fault::kScaleUnsettledTare):
    case static_cast<int>(Fault::kScaleGlitchOnLoad):
      if (!(duration > 0.0)) {
        message = "duration must be > 0 s for this fault";
        return false;
      }
      if (fault == static_cast<int>(Fault::kScaleGlitch)) {
        scale_.glitch(time() + duration);
        message = "scale readings are garbage and unstable for " + std::to_string(duration) + " s";
      } else if (fault == static_cast<int>(Fault::kScaleUnsettledTare)) {
        scale_.unsettledNextTare(duration);
        message = "the next tare catches the platform swinging: zero 3 g high, readings drift 3 g low over " +
                  std::to_string(duration) + " s";
      } else if (fault == static_cast<int>(Fault::kScaleGlitchOnLoad)) {
        scale_.glitchOnNextLoad(duration);
        message = "scale readings are garbage and unstable for " + std::to_string(duration) +
                  " s from when the next sherd lands on the scale";
      } else {
        camera_fault_until_ = time() + duration;
        message = "archival camera does not answer for " + std::to_string(duration) + " s";
      }
      return true;
    default:
      message = "unknown fault " + std::to_string(fault) +
                " (0 drop, 1 scale glitch, 2 camera timeout, 3 scale unsettled tare, 4 scale glitch on load)";
      return false;
  }
}

std::vector<SherdState> Simulator::groundTruth() const {
  std::vector<SherdState> out;
  for (size_t i = 0; i < world_->sherdCount(); ++i) out.push_back(world_->sherd(i));
  return out;
}

}  // namespace rascal_sim
