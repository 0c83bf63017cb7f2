// IK benchmark: median and 99th-percentile solve time and success rate of the closed-form and
// the KDL (Levenberg-Marquardt, multi-seed) solvers, on poses from random joint vectors inside the
// limits and on top-down grasp poses over the table. Fixed seeds.
//   rascal_control_bench_ik [urdf_path] [count]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "rascal_control/CollisionChecker.hpp"
#include "rascal_control/IkSolver.hpp"
#include "rascal_control/KinematicModel.hpp"
#include "rascal_control/TrajectoryPlanner.hpp"

using rascal_control::IkSolver;
using rascal_control::JointVector;
using rascal_control::KinematicModel;

namespace {

void report(const char* name, std::vector<double>& micros, int solved, int tried) {
  std::sort(micros.begin(), micros.end());
  const double median = micros[micros.size() / 2];
  const double p99 = micros[std::min(micros.size() - 1, static_cast<std::size_t>(0.99 * micros.size()))];
  std::printf("%-34s n=%6d  median %8.1f us  p99 %8.1f us  success %6.2f %%\n", name, tried, median,
              p99, 100.0 * solved / tried);
}

void run(const char* name, IkSolver& ik, IkSolver::Method method, const std::vector<KDL::Frame>& targets,
         const std::vector<JointVector>& seeds) {
  std::vector<double> micros;
  int solved = 0;
  for (std::size_t n = 0; n < targets.size(); ++n) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = ik.solve(targets[n], seeds[n], method);
    const auto t1 = std::chrono::steady_clock::now();
    micros.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    double position = 0.0, angle = 0.0;
    if (r.ok()) {
      IkSolver::frameError(targets[n], ik.model().forward(r.joints), position, angle);
      solved += (position < 0.0005 && angle < 0.005) ? 1 : 0;
    }
  }
  report(name, micros, solved, static_cast<int>(targets.size()));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : RASCAL_URDF_PATH;
  const int count = argc > 2 ? std::atoi(argv[2]) : 10000;
  const KinematicModel model = KinematicModel::fromFile(path);
  IkSolver ik(model);
  std::printf("IK benchmark, %s, %d poses per set, seeds from a home pose (all zeros)\n", path.c_str(), count);

  std::mt19937 rng(1);
  std::vector<KDL::Frame> random_targets, top_down;
  std::vector<JointVector> zero_seeds(count, JointVector{});
  for (int n = 0; n < count; ++n) {
    JointVector q{};
    for (std::size_t j = 0; j < rascal_control::kArmJoints; ++j) {
      std::uniform_real_distribution<double> u(model.limits()[j].lower, model.limits()[j].upper);
      q[j] = u(rng);
    }
    random_targets.push_back(model.forward(q));
  }
  std::uniform_real_distribution<double> ux(0.10, 0.42), uy(-0.35, 0.35), uz(0.0, 0.28), uyaw(-M_PI / 2, M_PI / 2);
  while (static_cast<int>(top_down.size()) < count) {
    const double x = ux(rng), y = uy(rng);
    if (std::hypot(x, y) < 0.12 || std::hypot(x, y) > 0.45) {
      continue;  // the table area RASCAL's stations use
    }
    top_down.push_back(IkSolver::topDown(x, y, uz(rng), uyaw(rng)));
  }
  run("random poses, analytic", ik, IkSolver::Method::Analytic, random_targets, zero_seeds);
  run("random poses, KDL LMA multi-seed", ik, IkSolver::Method::Numeric, random_targets, zero_seeds);
  run("top-down poses, analytic", ik, IkSolver::Method::Analytic, top_down, zero_seeds);
  run("top-down poses, KDL LMA multi-seed", ik, IkSolver::Method::Numeric, top_down, zero_seeds);

  // Planning time of whole moves between top-down poses (with the table as collision fixture).
  rascal_control::CollisionChecker checker(model);
  rascal_control::TrajectoryPlanner planner(model, ik, &checker);
  std::vector<double> joint_ms, linear_ms;
  int linear_ok = 0, tried = 0;
  for (int n = 0; n + 1 < static_cast<int>(top_down.size()) && tried < 200; n += 2) {
    const auto a = ik.solve(top_down[n], JointVector{});
    const auto b = ik.solve(top_down[n + 1], a.joints);
    if (!a.ok() || !b.ok()) {
      continue;
    }
    ++tried;
    auto t0 = std::chrono::steady_clock::now();
    planner.planJoint(a.joints, b.joints, 1.0);
    auto t1 = std::chrono::steady_clock::now();
    joint_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    t0 = std::chrono::steady_clock::now();
    linear_ok += planner.planLinear(a.joints, top_down[n + 1], 1.0).ok() ? 1 : 0;
    t1 = std::chrono::steady_clock::now();
    linear_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::sort(joint_ms.begin(), joint_ms.end());
  std::sort(linear_ms.begin(), linear_ms.end());
  std::printf("planning (IK done), %d top-down move pairs: joint median %.2f ms; linear median %.2f ms, "
              "p99 %.2f ms, %d planned (the rest cross a limit or singularity)\n",
              tried, joint_ms[joint_ms.size() / 2], linear_ms[linear_ms.size() / 2],
              linear_ms[static_cast<std::size_t>(0.99 * linear_ms.size())], linear_ok);
  return 0;
}
