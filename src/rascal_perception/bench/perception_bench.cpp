// Perception speed: median and 99th percentile time per 640 x 480 wrist frame for segmentation
// alone (SherdDetector::segment: background, fixtures, depth, blobs, splitting) and for a full
// detect (plus the plane, measurement, grasps, scores), on frames rendered by the simulator's
// core (generated scenes, 6..10 sherds, lighting 0.3 .. 1.5 x), with the parameters the node
// reads (the shipped config/rascal.yaml, the URDF's gripper). Run it on one core:
//   taskset -c 0 perception_bench [frames]
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "../test/SimScenes.hpp"
#include "rascal_perception/DetectorParameters.hpp"
#include "rascal_perception/SherdDetector.hpp"

using namespace rascal_perception;
using namespace rascal_perception_test;
using Clock = std::chrono::steady_clock;

namespace {
double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

/// CPU time of this thread [ms]: on a shared machine, wall time also counts other processes.
double cpuMs() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

void report(const char* what, std::vector<double> t) {
  std::sort(t.begin(), t.end());
  const double median = t[t.size() / 2];
  const double p99 = t[std::min(t.size() - 1, static_cast<size_t>(0.99 * (t.size() - 1) + 0.5))];
  std::printf("%-34s median %6.2f ms   p99 %6.2f ms   (%zu frames)\n", what, median, p99, t.size());
}
}  // namespace

int main(int argc, char** argv) {
  const int scenes = argc > 1 ? std::max(1, std::stoi(argv[1])) : 40;
  cv::setNumThreads(1);  // one core: no OpenCV worker threads competing for it
  const DetectorParameters params =
      DetectorParameters::read(rascal_workcell::Parameters::fromFile(RASCAL_CONFIG_PATH, "sherd_detector"),
                               rascal_workcell::GripperGeometry::fromPackageUrdf());
  const double surface_z = params.workcell.station(rascal_workcell::StationType::Pickup).surface_z;
  const int repeats = 5;
  std::vector<double> seg, det, seg_cpu, det_cpu;
  size_t sherds = 0;
  for (int i = 0; i < scenes; ++i) {
    const unsigned seed = 1000 + i;
    const double brightness = 0.3 + 1.2 * (i % 7) / 6.0;
    rascal_sim::Scenario sc = generated(seed, 6 + i % 5, brightness, 3000 + 1000 * (i % 6), 0.3);
    rascal_sim::Scenario empty = sc;
    empty.sherds.clear();
    const Frame cal = render(empty, surveyJoints());
    const Frame f = render(sc, surveyJoints());
    SherdDetector d{params.config};
    d.calibrate("pickup", cal.rgb, cal.depth, cal.view, surface_z);
    cv::Mat fg;
    for (int k = 0; k < repeats; ++k) {
      const double c0 = cpuMs();
      auto t0 = Clock::now();
      d.segment("pickup", f.rgb, f.depth, f.view, surface_z, fg);
      auto t1 = Clock::now();
      const double c1 = cpuMs();
      const DetectionResult r = d.detect("pickup", f.rgb, f.depth, f.view, surface_z);
      auto t2 = Clock::now();
      const double c2 = cpuMs();
      seg.push_back(ms(t1 - t0));
      det.push_back(ms(t2 - t1));
      seg_cpu.push_back(c1 - c0);
      det_cpu.push_back(c2 - c1);
      if (k == 0) sherds += r.sherds.size();
    }
  }
  std::printf("perception bench: %d scenes x %d runs, %zu sherds detected (%.1f per frame)\n", scenes, repeats,
              sherds, static_cast<double>(sherds) / scenes);
  report("segmentation (segment), wall", seg);
  report("full detect (detect), wall", det);
  report("segmentation (segment), CPU", seg_cpu);
  report("full detect (detect), CPU", det_cpu);
  return 0;
}
