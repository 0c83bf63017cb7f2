// Renders the wrist and archival views of a scenario to PNG (no ROS):
//   render_views <scenario.yaml> <out_dir> [archival_scale [exposure_ev]]
// The wrist view is taken from the survey height over the pickup mat with the gripper pointing
// down; the archival view has the scenario's first sherd moved to the camera station's place_at,
// the arm at its sleep pose (out of view). archival_scale < 1 shrinks the archival PNG for docs;
// exposure_ev shoots it that many stops brighter (+) or darker (-), as the capture service does.
// The layout and options are the shipped config/rascal.yaml's, the finger limits the URDF's.
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_sim/SimParameters.hpp"
#include "rascal_sim/Simulator.hpp"

using namespace rascal_sim;

namespace {
/// Joints that put ee_gripper_link at (x, y, z) pointing straight down (coarse-to-fine search),
/// the left finger at `finger`.
JointVector pointDown(double x, double y, double z, double finger) {
  const double waist = std::atan2(y, x), r = std::hypot(x, y);
  JointVector best{};
  double best_err = 1e9, step = 0.02, sh0 = -1.8, sh1 = 1.9, el0 = -2.1, el1 = 1.6;
  for (int pass = 0; pass < 4; ++pass) {
    for (double sh = sh0; sh <= sh1; sh += step) {
      for (double el = el0; el <= el1; el += step) {
        const JointVector q{waist, sh, el, 0, M_PI / 2 - sh - el, 0};
        if (q[4] < ArmKinematics::lowerLimits()[4] || q[4] > ArmKinematics::upperLimits()[4]) continue;
        const Eigen::Vector3d p = ArmKinematics::forward(q, finger)[kEeGripperLink].translation();
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

void save(const std::string& path, const cv::Mat& rgb) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(path, bgr)) throw std::runtime_error("cannot write " + path);
  std::printf("wrote %s (%d x %d)\n", path.c_str(), rgb.cols, rgb.rows);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: render_views <scenario.yaml> <out_dir> [archival_scale [exposure_ev]]\n");
    return 2;
  }
  try {
    const std::string data = RASCAL_SIM_DATA_DIR, out = argv[2];
    const double scale = argc > 3 ? std::stod(argv[3]) : 1.0;
    const double exposure_ev = argc > 4 ? std::stod(argv[4]) : 0.0;
    const SimParameters config = SimParameters::read(
        rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sim"),
        rascal_workcell::GripperGeometry::fromPackageUrdf(), data);
    const WorldLayout& layout = config.layout;
    const MunsellTable munsell(data + "/munsell_soil_hues_grid_renotation.csv");
    Scenario scenario = ScenarioLoader(layout, munsell).load(argv[1]);

    SimulatorOptions o = config.options;
    o.wrist_camera = true;
    // survey pose over the pickup mat: camera about 0.28 m up (config survey.z)
    const Eigen::Vector2d pickup = layout.station(StationType::Pickup).area.centre;
    o.initial_joints = pointDown(pickup.x() - 0.05, pickup.y(), 0.28, o.initial_finger);
    Simulator wrist(layout, o);
    wrist.load(scenario);
    for (int i = 0; i < 300; ++i) wrist.step();
    while (!wrist.wristFrameDue()) wrist.step();
    save(out + "/sim_wrist.png", wrist.renderWristFrame().rgb);

    if (!scenario.sherds.empty()) {
      const Eigen::Vector2d place = layout.station(StationType::ArchivalCamera).place_at;
      scenario.sherds[0].pose = {place.x(), place.y(), 0.4};
    }
    SimulatorOptions a = config.options;
    a.wrist_camera = false;
    Simulator archival(layout, a);
    archival.load(scenario);
    for (int i = 0; i < 300; ++i) archival.step();
    cv::Mat img = archival.renderArchival(exposure_ev);
    if (scale > 0 && scale < 1) cv::resize(img, img, cv::Size(), scale, scale, cv::INTER_AREA);
    save(out + "/sim_archival.png", img);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_views: %s\n", e.what());
    return 1;
  }
  return 0;
}
