// Perception speed: median and 99th percentile time per 640 x 480 wrist frame for segmentation
// alone (SherdDetector::segment: background, fixtures, depth, blobs, splitting) and for a full
// detect (plus the plane, measurement, grasps, scores), on frames rendered by the simulator's
// core (generated scenes, 6..10 sherds, lighting 0.3 .. 1.5 x), with the parameters the node
// reads (the shipped config/rascal.yaml, the URDF's gripper); then, with --photos DIR, the photo
// segmentation (PhotoSegmenter + ScaleBarFinder) on every photo of DIR/photos_truth.json: the
// count against the hand range, px/cm against the hand reading, and the CPU time per photo.
// --dump DIR writes the wrist frames it timed (PNG), so bench/perception can time the paper's
// pipeline on the same frames. Run it on one core:
//   taskset -c 0 perception_bench [frames] [--photos DIR] [--dump DIR]
#include <time.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "../test/SimScenes.hpp"
#include "rascal_perception/DetectorParameters.hpp"
#include "rascal_perception/PhotoSegmenter.hpp"
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

double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t.empty() ? 0.0 : t[t.size() / 2];
}

/// Every photo of `dir`/photos_truth.json through the photo segmentation; returns the median
/// CPU time per photo [ms].
double photos(const std::string& dir) {
  cv::FileStorage truth(dir + "/photos_truth.json", cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);
  if (!truth.isOpened()) {
    std::fprintf(stderr, "perception_bench: cannot read %s/photos_truth.json\n", dir.c_str());
    return 0.0;
  }
  std::printf("\nreal photos (%s): one core, CPU time per photo (median of 3 runs)\n", dir.c_str());
  std::printf("%-38s %5s %10s %8s %8s %8s\n", "photo", "found", "hand", "px/cm", "hand", "ms");
  const PhotoSegmenter segmenter{PhotoSegmenter::Options()};
  std::vector<double> all;
  int in_range = 0, total = 0, bars = 0, bars_ok = 0;
  for (const cv::FileNode& n : truth.root()) {
    const std::string name = n.name();
    cv::Mat bgr = cv::imread(dir + "/" + name, cv::IMREAD_COLOR), rgb;
    if (bgr.empty()) continue;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    std::vector<double> t;
    PhotoResult r;
    for (int k = 0; k < 3; ++k) {
      const double c0 = cpuMs();
      r = segmenter.segment(rgb);
      t.push_back(cpuMs() - c0);
    }
    const int lo = static_cast<int>(n["count_range"][0]), hi = static_cast<int>(n["count_range"][1]);
    const double hand = n["px_per_cm"].empty() ? 0.0 : static_cast<double>(n["px_per_cm"]);
    const int found = static_cast<int>(r.sherds.size());
    const bool ok = lo <= found && found <= hi;
    const bool bar_ok = hand > 0 && r.bar.found && std::fabs(r.bar.px_per_cm / hand - 1.0) < 0.02;
    in_range += ok;
    ++total;
    bars += hand > 0;
    bars_ok += bar_ok;
    all.push_back(median(t));
    char range[32], ppc[16];
    std::snprintf(range, sizeof(range), "%d..%d", lo, hi);
    std::snprintf(ppc, sizeof(ppc), r.bar.found ? "%.2f" : "-", r.bar.px_per_cm);
    std::printf("%-38s %5d %10s %8s %8.2f %8.1f%s\n", name.c_str(), found, range, ppc, hand, median(t),
                ok ? (hand > 0 && !bar_ok ? "   <- px/cm" : "") : "   <- count");
  }
  std::printf("photos: count within the hand range %d of %d, px/cm within 2 %% %d of %d; CPU per photo median %.1f "
              "ms, max %.1f ms\n",
              in_range, total, bars_ok, bars, median(all), all.empty() ? 0.0 : *std::max_element(all.begin(), all.end()));
  return median(all);
}

void report(const char* what, std::vector<double> t) {
  std::sort(t.begin(), t.end());
  const double median = t[t.size() / 2];
  const double p99 = t[std::min(t.size() - 1, static_cast<size_t>(0.99 * (t.size() - 1) + 0.5))];
  std::printf("%-34s median %6.2f ms   p99 %6.2f ms   (%zu frames)\n", what, median, p99, t.size());
}
}  // namespace

int main(int argc, char** argv) {
  int scenes = 40;
  std::string photo_dir, dump_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--photos" && i + 1 < argc) {
      photo_dir = argv[++i];
    } else if (a == "--dump" && i + 1 < argc) {
      dump_dir = argv[++i];
    } else {
      scenes = std::max(1, std::stoi(a));
    }
  }
  cv::setNumThreads(1);  // one core: no OpenCV worker threads competing for it
  const DetectorParameters& params = rascal_perception_test::shippedDetector();
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
    if (!dump_dir.empty()) {
      cv::Mat bgr;
      cv::cvtColor(f.rgb, bgr, cv::COLOR_RGB2BGR);
      cv::imwrite(dump_dir + "/frame_" + std::to_string(i) + ".png", bgr);
      cv::cvtColor(cal.rgb, bgr, cv::COLOR_RGB2BGR);
      cv::imwrite(dump_dir + "/empty_" + std::to_string(i) + ".png", bgr);
    }
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
  // one line for bench/perception to compare with the paper's pipeline
  double photo_ms = 0.0;
  if (!photo_dir.empty()) photo_ms = photos(photo_dir);
  std::printf("cpp_ms frame_segment=%.3f frame_detect=%.3f photo=%.3f\n", median(seg_cpu), median(det_cpu), photo_ms);
  return 0;
}
