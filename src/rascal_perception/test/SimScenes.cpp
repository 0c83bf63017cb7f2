#include "SimScenes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/ScenarioGenerator.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_sim/SherdMeshBuilder.hpp"
#include "rascal_sim/Simulator.hpp"
#include "rascal_sim/SlipModel.hpp"

using namespace rascal_sim;

namespace rascal_perception_test {

const rascal_perception::DetectorParameters& shippedDetector() {
  static const rascal_perception::DetectorParameters p = rascal_perception::DetectorParameters::read(
      rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sherd_detector"),
      rascal_workcell::GripperGeometry::fromPackageUrdf());
  return p;
}

const SimParameters& simParameters() {
  static const SimParameters p =
      SimParameters::read(rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sim"),
                          rascal_workcell::GripperGeometry::fromPackageUrdf(), RASCAL_SIM_DATA_DIR);
  return p;
}

const WorldLayout& layout() { return simParameters().layout; }

const rascal_workcell::Station& station(rascal_workcell::StationType type) { return layout().station(type); }

namespace {
double fingersOpen() { return simParameters().options.gripper.finger_max; }
}  // namespace

static const MunsellTable& munsell() {
  static const MunsellTable m(std::string(RASCAL_SIM_DATA_DIR) + "/munsell_soil_hues_grid_renotation.csv");
  return m;
}

JointVector pointDown(double x, double y, double z) {
  const double waist = std::atan2(y, x), r = std::hypot(x, y);
  JointVector best{};
  double best_err = 1e9, step = 0.02, sh0 = -1.8, sh1 = 1.9, el0 = -2.1, el1 = 1.6;
  for (int pass = 0; pass < 4; ++pass) {
    for (double sh = sh0; sh <= sh1; sh += step) {
      for (double el = el0; el <= el1; el += step) {
        const JointVector q{waist, sh, el, 0, M_PI / 2 - sh - el, 0};
        if (q[4] < ArmKinematics::lowerLimits()[4] || q[4] > ArmKinematics::upperLimits()[4]) continue;
        const Eigen::Vector3d p = ArmKinematics::forward(q, fingersOpen())[kEeGripperLink].translation();
        const double err = std::hypot(std::hypot(p.x(), p.y()) - r, p.z() - z);
        if (err < best_err) {
          best_err = err;
          best = q;
        }
      }
    }
    sh0 = best[1] - 2 * step, sh1 = best[1] + 2 * step, el0 = best[2] - 2 * step, el1 = best[2] + 2 * step;
    step /= 5;
  }
  return best;
}

JointVector cameraOver(const Eigen::Vector2d& goal, double ee_z) {
  // wrist_rotate undoes the waist; the gripper goes where the camera's offset from it puts the
  // camera over the goal
  Eigen::Vector2d target = goal;
  JointVector j{};
  for (int i = 0; i < 3; ++i) {
    j = pointDown(target.x(), target.y(), ee_z);
    j[5] = -j[0];
    const auto T = ArmKinematics::forward(j, fingersOpen());
    target += goal - T[kCameraColorOpticalFrame].translation().head<2>();
  }
  return j;
}

const JointVector& surveyJoints() {
  static const JointVector q = cameraOver(station(StationType::Pickup).area.centre);
  return q;
}

bool fullyInView(const Truth& t, const rascal_perception::CameraView& view) {
  const Eigen::Isometry3d cam_T_base = view.base_T_camera.inverse();
  const double r = 0.5 * std::hypot(t.length, t.width) + 0.003;
  for (int k = 0; k < 16; ++k) {
    const double a = k * M_PI / 8;
    const Eigen::Vector3d p(t.centre.x() + r * std::cos(a), t.centre.y() + r * std::sin(a), 0.0);
    const Eigen::Vector2d uv = view.intrinsics.project(cam_T_base * p);
    if (uv.x() < 5 || uv.y() < 5 || uv.x() > view.intrinsics.width - 5 || uv.y() > view.intrinsics.height - 5) {
      return false;
    }
  }
  return true;
}

int falseParts(const Frame& f, const std::vector<rascal_perception::Leftover>& leftovers, int* parts) {
  int false_parts = 0;
  for (const rascal_perception::Leftover& l : leftovers) {
    if (!l.cut_by_border) continue;
    const bool part = std::any_of(f.truth.begin(), f.truth.end(), [&](const Truth& t) {
      return !fullyInView(t, f.view) && (l.position.head<2>() - t.centre).norm() <= 0.5 * std::hypot(t.length, t.width);
    });
    if (part && parts) ++*parts;
    if (!part) ++false_parts;
  }
  return false_parts;
}

int wholeLeftovers(const std::vector<rascal_perception::Leftover>& leftovers) {
  return static_cast<int>(std::count_if(leftovers.begin(), leftovers.end(),
                                        [](const rascal_perception::Leftover& l) { return !l.cut_by_border; }));
}

Frame render(const Scenario& scenario, const JointVector& q, double settle_s) {
  // one simulator per arm pose, reloaded with each scenario (building one costs more than a frame)
  static std::map<JointVector, std::unique_ptr<Simulator>> cache;
  std::unique_ptr<Simulator>& cached = cache[q];
  if (!cached) {
    SimulatorOptions o = simParameters().options;
    o.initial_joints = q;
    o.archival_width = 64;
    o.archival_height = 48;
    cached = std::make_unique<Simulator>(layout(), o);
  }
  Simulator& sim = *cached;
  sim.load(scenario);
  for (const double until = sim.time() + settle_s; sim.time() < until;) sim.step();
  WristFrame w = sim.renderWristFrame();
  Frame f;
  f.rgb = w.rgb;
  f.depth = w.depth_mm;
  const CameraModel& m = sim.wristModel();
  f.view.intrinsics = {m.width, m.height, m.fx, m.fy, m.cx, m.cy};
  f.view.base_T_camera = w.world_T_camera;
  for (const SherdState& s : sim.groundTruth()) {
    Truth t;
    t.name = s.name;
    t.centre = s.pose.translation().head<2>();
    const Eigen::Vector3d x = s.pose.linear().col(0);
    t.yaw = std::atan2(x.y(), x.x());
    t.length = s.length;
    t.width = s.width;
    t.top = s.pose.translation().z() + 0.5 * s.box_size.z();
    t.thickness = s.thickness;
    t.curvature = s.curvature;
    t.curvature_long = s.curvature_long;
    t.convex_up = s.convex_up;
    std::vector<cv::Point2f> poly;
    for (const Eigen::Vector2d& p : s.outline) {
      const Eigen::Vector3d w = s.pose * Eigen::Vector3d(p.x(), p.y(), 0.0);
      t.outline.push_back(w.head<2>());
      poly.emplace_back(static_cast<float>(w.x() * 1e3), static_cast<float>(w.y() * 1e3));
    }
    if (poly.size() >= 3) {
      const cv::Moments m = cv::moments(poly);
      t.principal_yaw = 0.5 * std::atan2(2.0 * m.mu11, m.mu20 - m.mu02);
    }
    t.rotation = s.pose.linear();
    t.own_axes = rascal_sim::SherdMeshBuilder::principalAxes(s.outline);
    f.truth.push_back(t);
  }
  return f;
}

double Truth::ownElongation() const { return rascal_sim::SlipModel::elongation(own_axes); }

double Truth::closingAlong(const Eigen::Vector3d& closing) const {
  return rascal_sim::SlipModel::closingAlong(rotation.transpose() * closing, own_axes);
}

void Truth::extents(double yaw, double& l, double& w, Eigen::Vector2d& c) const {
  const Eigen::Vector2d a(std::cos(yaw), std::sin(yaw)), b(-std::sin(yaw), std::cos(yaw));
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  for (const Eigen::Vector2d& p : outline) {
    u0 = std::min(u0, a.dot(p)), u1 = std::max(u1, a.dot(p)), v0 = std::min(v0, b.dot(p)), v1 = std::max(v1, b.dot(p));
  }
  l = u1 - u0;
  w = v1 - v0;
  c = 0.5 * (u0 + u1) * a + 0.5 * (v0 + v1) * b;
}

namespace {
/// `g`'s sherds on the pickup mat under generated lighting; `name` with the seed appended.
Scenario generatedWith(const std::string& name, unsigned seed, double brightness, double kelvin, double shadow,
                       GeneratorOptions g) {
  Scenario sc;
  sc.name = name + std::to_string(seed);
  sc.seed = seed;
  sc.lighting.brightness = brightness;
  sc.lighting.colour_temperature = kelvin;
  sc.lighting.shadow_strength = shadow;
  sc.lighting.shadow_radius = 0.07;
  sc.lighting.shadow_start = station(StationType::Pickup).area.centre + Eigen::Vector2d(0.02 * (seed % 5) - 0.04, 0.0);
  g.seed = seed;
  g.area = station(StationType::Pickup).area;
  sc.sherds = ScenarioGenerator(munsell()).generate(g);
  return sc;
}
}  // namespace

Scenario generated(unsigned seed, int count, double brightness, double kelvin, double shadow, int touching_pairs) {
  GeneratorOptions g;
  g.count = count;
  g.touching_pairs = touching_pairs;
  return generatedWith("generated_", seed, brightness, kelvin, shadow, g);
}

Scenario generatedHeap(unsigned seed, int count, double spread) {
  GeneratorOptions g;
  g.count = count;
  g.heap = true;
  g.heap_centre = station(StationType::Pickup).area.centre;
  g.heap_spread = spread;
  g.heap_drop_height = 0.01;
  return generatedWith("heap_", seed, 1.0, 5600, 0.0, g);
}

namespace {
std::vector<Eigen::Vector2d> placed(const SherdSpec& s) {
  const Eigen::Rotation2Dd r(s.pose.z());
  std::vector<Eigen::Vector2d> out;
  for (const Eigen::Vector2d& p : s.outline) out.push_back(s.pose.head<2>() + r * p);
  return out;
}

double gap(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  double best = 1e9;
  for (int pass = 0; pass < 2; ++pass) {
    const auto& p = pass ? b : a;
    const auto& q = pass ? a : b;
    for (const Eigen::Vector2d& v : p) {
      for (size_t k = 0; k < q.size(); ++k) {
        const Eigen::Vector2d s0 = q[k], s1 = q[(k + 1) % q.size()];
        const double t = std::clamp((v - s0).dot(s1 - s0) / (s1 - s0).squaredNorm(), 0.0, 1.0);
        best = std::min(best, (s0 + t * (s1 - s0) - v).norm());
      }
    }
  }
  return best;
}
}  // namespace

void makeTouching(Scenario& sc, size_t i, size_t j) {
  SherdSpec& b = sc.sherds[j];
  const Eigen::Vector2d dir = (sc.sherds[i].pose.head<2>() - b.pose.head<2>()).normalized();
  const auto a = placed(sc.sherds[i]);
  for (int k = 0; k < 1000 && gap(a, placed(b)) > 0.0003; ++k) b.pose.head<2>() += 0.0002 * dir;
}

Scenario loadScenario(const std::string& file) {
  return ScenarioLoader(layout(), munsell()).load(std::string(RASCAL_PERCEPTION_SCENARIOS) + "/" + file);
}

}  // namespace rascal_perception_test
