// Real-time factor of the simulator core on this machine: 10 sherds, the arm moving between
// stations, wrist camera off and then rendering at 30 Hz (no ROS; the node adds message costs).
// The layout and options are the shipped config/rascal.yaml's.
//   sim_speed [scenario.yaml] [sim_seconds]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/ScenarioLoader.hpp"
#include "rascal_sim/SimParameters.hpp"
#include "rascal_sim/Simulator.hpp"

using namespace rascal_sim;

namespace {
double run(const SimParameters& config, const Scenario& scenario, bool camera, double seconds, int& frames,
           double& render_ms) {
  SimulatorOptions o = config.options;
  o.wrist_camera = camera;
  o.wrist_rate = 30.0;
  Simulator sim(config.layout, o);
  sim.load(scenario);
  // a move every 2 s between a pose over the pickup mat and one over the scale
  const JointVector a{0.9, 0.2, 0.3, 0.0, 1.0, 0.0}, b{0.0, 0.3, 0.2, 0.0, 1.0, 0.0};
  frames = 0;
  double render = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  int leg = 0;
  while (sim.time() < seconds) {
    if (sim.time() >= leg * 2.0) {
      TrajectoryPoint p;
      p.positions = (leg % 2) ? a : b;
      p.time_from_start = 1.5;
      sim.commandArm(sim.time(), {p}, {true, true, true, true, true, true});
      ++leg;
    }
    sim.step();
    if (sim.wristFrameDue()) {
      const auto r0 = std::chrono::steady_clock::now();
      const WristFrame f = sim.renderWristFrame();
      render += std::chrono::duration<double>(std::chrono::steady_clock::now() - r0).count();
      frames += f.rgb.empty() ? 0 : 1;
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  render_ms = frames ? 1000.0 * render / frames : 0.0;
  return seconds / wall;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string data = RASCAL_SIM_DATA_DIR;
    const std::string path = argc > 1 ? argv[1] : data + "/../../../config/scenarios/demo_10.yaml";
    const double seconds = argc > 2 ? std::stod(argv[2]) : 20.0;
    const SimParameters config = SimParameters::read(rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sim"),
                                                     rascal_workcell::GripperGeometry::fromPackageUrdf(), data);
    const MunsellTable munsell(data + "/munsell_soil_hues_grid_renotation.csv");
    const Scenario scenario = ScenarioLoader(config.layout, munsell).load(path);
    int frames = 0;
    double render_ms = 0.0;
    const double off = run(config, scenario, false, seconds, frames, render_ms);
    std::printf("scenario %s: %zu sherds, %.0f s simulated, %.0f ms physics step\n", scenario.name.c_str(),
                scenario.sherds.size(), seconds, 1000.0 * config.options.physics_dt);
    std::printf("core, wrist camera off:          real-time factor %.1fx\n", off);
    const double on = run(config, scenario, true, seconds, frames, render_ms);
    std::printf("core, wrist camera 30 Hz RGB-D:  real-time factor %.1fx (%d frames, %.1f ms per frame)\n", on,
                frames, render_ms);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sim_speed: %s\n", e.what());
    return 1;
  }
  return 0;
}
