#include "rascal_perception/SherdDetector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "StoredFields.hpp"

namespace rascal_perception {

namespace {
bool samePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm() < 1e-4 && (a.linear() - b.linear()).norm() < 1e-4;
}

/// [m] the top of `blob` above the table plane: the 90th percentile of its pixels' heights
/// (a few flying pixels at its edge do not count); 0 without a height map.
double topHeight(const Blob& blob, const cv::Mat& height) {
  if (height.empty()) return 0.0;
  std::vector<float> h;
  for (int r = 0; r < blob.mask.rows; ++r) {
    for (int c = 0; c < blob.mask.cols; ++c) {
      if (!blob.mask.at<uint8_t>(r, c)) continue;
      const float v = height.at<float>(r + blob.bounds.y, c + blob.bounds.x);
      if (v == v) h.push_back(v);
    }
  }
  if (h.empty()) return 0.0;
  const size_t k = h.size() * 9 / 10;
  std::nth_element(h.begin(), h.begin() + k, h.end());
  return std::max(0.0f, h[k]);
}
}  // namespace

SherdDetector::SherdDetector(const PerceptionConfig& config)
    : config_(config), measurer_(config), planner_(config) {}

const BackgroundModel* SherdDetector::model(const std::string& station) const {
  auto it = stations_.find(station);
  return it == stations_.end() ? nullptr : &it->second.model;
}

double SherdDetector::pixelsPerMetre(const CameraView& view, double surface_z) const {
  Eigen::Vector3d p;
  const CameraIntrinsics& k = view.intrinsics;
  if (!SherdMeasurer::intersect(view, Eigen::Vector4d(0, 0, 1, -surface_z), 0.0, k.cx, k.cy, p)) {
    return k.fx / 0.3;
  }
  const double z = (view.base_T_camera.inverse() * p).z();
  return k.fx / std::max(z, 0.01);
}

cv::Mat SherdDetector::raised(const cv::Mat& depth_mm, const CameraView& view, double surface_z) {
  if (depth_mm.empty()) return cv::Mat();
  if ((ray_z_rotation_ - view.base_T_camera.linear()).norm() > 1e-9 || ray_z_.size() != depth_mm.size()) {
    ray_z_ = SherdMeasurer::rayZMap(view);
    ray_z_rotation_ = view.base_T_camera.linear();
    ray_z_rotation_changed_ = true;
  }
  const float cam_z = static_cast<float>(view.base_T_camera.translation().z() - surface_z);
  const float min_h = static_cast<float>(config_.min_sherd_height);
  if (raised_below_.size() != depth_mm.size() || raised_cam_z_ != cam_z || ray_z_rotation_changed_) {
    // raised: cam_z + ray_z * depth > min_h; a ray looking down (ray_z < 0) meets that for
    // depths below (min_h - cam_z) / ray_z, one looking up for any depth
    raised_below_.create(depth_mm.size(), CV_16U);
    for (int y = 0; y < depth_mm.rows; ++y) {
      const float* r = ray_z_.ptr<float>(y);
      uint16_t* o = raised_below_.ptr<uint16_t>(y);
      for (int x = 0; x < depth_mm.cols; ++x) {
        const float below = r[x] < 0.0f ? 1000.0f * (min_h - cam_z) / r[x] : 65535.0f;
        o[x] = static_cast<uint16_t>(std::clamp(std::ceil(below), 0.0f, 65535.0f));  // integer d < below
      }
    }
    raised_cam_z_ = cam_z;
    ray_z_rotation_changed_ = false;
  }
  const uint16_t lo = static_cast<uint16_t>(config_.depth_min * 1000.0);
  const uint16_t hi = static_cast<uint16_t>(std::min(65535.0, config_.depth_max * 1000.0));
  cv::Mat out, valid;
  cv::compare(depth_mm, raised_below_, out, cv::CMP_LT);
  cv::inRange(depth_mm, cv::Scalar(lo), cv::Scalar(hi), valid);
  out &= valid;
  // a sherd is never thinner than a few pixels: drop isolated noise
  cv::morphologyEx(out, out, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  return out;
}

CalibrationResult SherdDetector::calibrate(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                                           const CameraView& view, double surface_z) {
  CalibrationResult r;
  if (rgb.empty() || rgb.type() != CV_8UC3) {
    r.message = "no colour image (need rgb8)";
    return r;
  }
  BackgroundOptions o;
  o.clusters = config_.background_clusters;
  o.hue_tolerance = config_.hue_tolerance;
  o.saturation_tolerance = config_.saturation_tolerance;
  o.min_value = config_.min_value;
  Station s;
  try {
    s.model.learn(rgb, o);
  } catch (const std::exception& e) {
    r.message = std::string("station ") + station + ": " + e.what();
    return r;
  }
  s.view = view;
  s.surface_z = surface_z;
  s.fixture = s.model.fixtureMask().clone();
  const cv::Mat up = raised(depth_mm, view, surface_z);
  if (!up.empty()) s.fixture |= up;  // anything standing on the empty station is a fixture too
  const int px = static_cast<int>(std::lround(config_.fixture_dilation * pixelsPerMetre(view, surface_z)));
  if (px > 0) {
    cv::dilate(s.fixture, s.fixture, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * px + 1, 2 * px + 1)));
  }
  r.success = true;
  r.clusters = static_cast<int>(s.model.clusters().size());
  r.fixture_fraction = static_cast<double>(cv::countNonZero(s.fixture)) / s.fixture.total();
  char buf[160];
  std::snprintf(buf, sizeof(buf), "station %s: %d background clusters, %.1f %% of the image masked as fixture",
                station.c_str(), r.clusters, 100.0 * r.fixture_fraction);
  r.message = buf;
  stations_[station] = std::move(s);
  return r;
}

bool SherdDetector::write(const std::string& station, cv::FileStorage& fs) const {
  auto it = stations_.find(station);
  if (it == stations_.end()) return false;
  const Station& s = it->second;
  const CameraIntrinsics& k = s.view.intrinsics;
  cv::Mat pose;
  cv::eigen2cv(Eigen::Matrix4d(s.view.base_T_camera.matrix()), pose);
  fs << "view" << "{" << "width" << k.width << "height" << k.height << "fx" << k.fx << "fy" << k.fy << "cx" << k.cx
     << "cy" << k.cy << "base_T_camera" << pose << "}";
  fs << "surface_z" << s.surface_z << "station_fixture" << s.fixture;
  fs << "model" << "{";
  s.model.write(fs);
  fs << "}";
  return true;
}

void SherdDetector::read(const std::string& station, const cv::FileNode& node) {
  const std::string where = "station " + station;
  const cv::FileNode v = node["view"];
  cv::Mat pose, fixture;
  if (!v.empty()) v["base_T_camera"] >> pose;
  node["station_fixture"] >> fixture;
  if (v.empty() || pose.rows != 4 || pose.cols != 4 || pose.type() != CV_64F || fixture.empty() ||
      fixture.type() != CV_8U) {
    throw std::invalid_argument(where + ": view or fixture mask missing");
  }
  Station s;
  CameraIntrinsics& k = s.view.intrinsics;
  k.width = storedInt(v, "width", where + " view");
  k.height = storedInt(v, "height", where + " view");
  k.fx = storedNumber(v, "fx", where + " view");
  k.fy = storedNumber(v, "fy", where + " view");
  k.cx = storedNumber(v, "cx", where + " view");
  k.cy = storedNumber(v, "cy", where + " view");
  Eigen::Matrix4d m;
  cv::cv2eigen(pose, m);
  s.view.base_T_camera.matrix() = m;
  s.surface_z = storedNumber(node, "surface_z", where);
  s.model.read(node["model"]);
  if (fixture.size() != s.model.seenMap().size()) {
    throw std::invalid_argument(where + ": fixture mask and seen-map differ in size");
  }
  s.fixture = fixture;
  stations_[station] = std::move(s);
}

CalibrationResult SherdDetector::refresh(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                                         const CameraView& view, double surface_z) {
  CalibrationResult r;
  auto it = stations_.find(station);
  if (it == stations_.end()) {
    r.message = "station " + station + " has no background model: calibrate it first";
    return r;
  }
  cv::Mat fg;
  segment(station, rgb, depth_mm, view, surface_z, fg);
  cv::dilate(fg, fg, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(15, 15)));
  fg |= fixture_;
  it->second.model.refresh(rgb, fg);
  r.success = true;
  r.clusters = static_cast<int>(it->second.model.clusters().size());
  r.fixture_fraction = static_cast<double>(cv::countNonZero(it->second.fixture)) / it->second.fixture.total();
  r.message = "station " + station + ": background colours refreshed";
  return r;
}

void SherdDetector::warpPriors(const Station& s, const CameraView& view, double surface_z, cv::Mat& allowed,
                               cv::Mat& fixture) const {
  const cv::Size size(view.intrinsics.width, view.intrinsics.height);
  if (samePose(s.view.base_T_camera, view.base_T_camera) && s.fixture.size() == size) {
    allowed = s.model.seenMap();
    fixture = s.fixture;
    return;
  }
  // pixel of this view -> point on the station plane -> pixel of the calibration view
  const Eigen::Vector4d plane(0, 0, 1, -surface_z);
  std::vector<cv::Point2f> here, there;
  const Eigen::Isometry3d calib_T_base = s.view.base_T_camera.inverse();
  const float w = static_cast<float>(size.width), h = static_cast<float>(size.height);
  for (const cv::Point2f& p : {cv::Point2f(0, 0), cv::Point2f(w, 0), cv::Point2f(w, h), cv::Point2f(0, h)}) {
    Eigen::Vector3d q;
    if (!SherdMeasurer::intersect(view, plane, 0.0, p.x, p.y, q)) continue;
    const Eigen::Vector3d c = calib_T_base * q;
    if (c.z() <= 0) continue;
    const Eigen::Vector2d uv = s.view.intrinsics.project(c);
    here.push_back(p);
    there.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
  }
  if (here.size() < 4) {  // the station plane is not under this view: no priors
    allowed = cv::Mat();
    fixture = cv::Mat();
    return;
  }
  const cv::Mat H = cv::getPerspectiveTransform(here, there);
  cv::warpPerspective(s.model.seenMap(), allowed, H, size, cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(0xFF));
  cv::warpPerspective(s.fixture, fixture, H, size, cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT,
                      cv::Scalar(0));
}

SegmentationOptions SherdDetector::segmentationOptions(const CameraView& view, double surface_z) const {
  const double ppm = pixelsPerMetre(view, surface_z);
  SegmentationOptions o;
  o.min_side_px = 0.7 * config_.min_sherd_size * ppm;
  o.max_side_px = 1.5 * config_.max_sherd_size * ppm;
  o.border_margin = config_.border_margin;
  o.split_min_neck = config_.split_min_neck;
  return o;
}

std::vector<Blob> SherdDetector::segment(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                                         const CameraView& view, double surface_z, cv::Mat& foreground,
                                         SegmentationStats* stats, bool check) {
  auto it = stations_.find(station);
  if (it == stations_.end()) {
    throw std::logic_error("SherdDetector::segment: station " + station + " has no background model");
  }
  const Station& s = it->second;
  warpPriors(s, view, surface_z, allowed_, fixture_);
  SegmentationOptions o = segmentationOptions(view, surface_z);
  o.check = check;
  return segmenter_.segment(rgb, s.model, allowed_, fixture_, raised(depth_mm, view, surface_z), o, foreground,
                            stats);
}

DetectionResult SherdDetector::detect(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                                      const CameraView& view, double surface_z) {
  DetectionResult r;
  if (!calibrated(station)) {
    r.message = "station " + station + " has no background model: call calibrate_background first";
    return r;
  }
  if (rgb.empty() || rgb.type() != CV_8UC3) {
    r.message = "no colour image (need rgb8)";
    return r;
  }
  if (!depth_mm.empty() && (depth_mm.type() != CV_16UC1 || depth_mm.size() != rgb.size())) {
    r.message = "the depth image must be 16UC1 and the size of the colour image";
    return r;
  }
  cv::Mat foreground;
  SegmentationStats stats;
  // with depth, a blob too big or cut by the border may be a heap with whole sherds in it: it is
  // cut apart first (below) and each part checked
  const std::vector<Blob> blobs = segment(station, rgb, depth_mm, view, surface_z, foreground, &stats, depth_mm.empty());
  const SegmentationOptions checks = segmentationOptions(view, surface_z);
  r.splits = stats.splits;
  cv::bitwise_not(foreground, usable_);
  if (!fixture_.empty()) usable_.setTo(0, fixture_);
  const PlaneFit plane = depth_mm.empty() ? PlaneFit() : measurer_.fitPlane(depth_mm, usable_, view, surface_z);
  r.plane = plane.ok ? plane.plane : Eigen::Vector4d(0, 0, 1, -surface_z);
  r.plane_inliers = plane.inliers;
  // sherds on sherds (a tipped-out bag): one blob, cut apart where the depth steps by a wall
  const cv::Mat height =
      depth_mm.empty() ? cv::Mat()
                       : StackSplitter::heightMap(depth_mm, view, r.plane, config_.depth_min, config_.depth_max);
  StackOptions stack;
  const double ppm = pixelsPerMetre(view, surface_z);
  stack.min_area_px = static_cast<int>(0.5 * std::pow(config_.min_sherd_size * ppm, 2));
  // something seen whole but not offered: where it lies and why, for the task layer to say
  // `measured`: the measurer's outline and height where it got that far (its width, from the
  // depth, is the strip's own; the image box of a standing sherd also holds a side face);
  // `cut`: only part of it in view (its box says nothing about standing on its edge)
  auto leave = [&](const Blob& b, const std::string& why, const SherdDetection* measured = nullptr,
                   bool cut = false) {
    Leftover l;
    l.why = why;
    l.cut_by_border = cut;
    l.length = std::max(b.box.size.width, b.box.size.height) / ppm;
    l.width = std::min(b.box.size.width, b.box.size.height) / ppm;
    if (!SherdMeasurer::intersect(view, r.plane, 0.0, b.box.center.x, b.box.center.y, l.position)) return;
    // its long side's direction on the surface: the box's long side, its end taken to the plane
    cv::Point2f q[4];
    b.box.points(q);
    const cv::Point2f side = cv::norm(q[1] - q[0]) >= cv::norm(q[2] - q[1]) ? q[1] - q[0] : q[2] - q[1];
    Eigen::Vector3d end;
    if (SherdMeasurer::intersect(view, r.plane, 0.0, b.box.center.x + side.x / 2, b.box.center.y + side.y / 2, end)) {
      l.yaw = wrapHalfPi(std::atan2(end.y() - l.position.y(), end.x() - l.position.x()));
    }
    l.height = topHeight(b, height);
    const bool strip = measured && measured->width > 0.0 && measured->height > measured->width;
    // a sherd on its edge is as tall as a pickable sherd is wide; a thick chip is not
    l.on_edge = !cut && (l.height > l.width || strip) && l.height >= config_.min_sherd_size;
    if (l.on_edge && l.why.find("edge") == std::string::npos) l.why += "; taller than wide: standing on its edge?";
    r.leftovers.push_back(std::move(l));
  };
  std::vector<Blob> offered;  // the outline of each of r.sherds, and the blob it was cut from
  std::vector<int> group;
  for (size_t blob = 0; blob < blobs.size(); ++blob) {
    const std::vector<StackPart> parts = stacks_.split(blobs[blob], height, stack);
    r.splits += static_cast<int>(parts.size()) - 1;
    for (const StackPart& part : parts) {
      if (!depth_mm.empty()) {
        const BlobCheck verdict = SherdSegmenter::check(part.blob, rgb.size(), checks);
        if (verdict == BlobCheck::kCutByBorder) {
          // another view of the survey may see it whole; if none does (a sherd across the mat's
          // edge), the task layer looks again centred on the part
          ++stats.rejected_border;
          leave(part.blob, "cut by the image border", nullptr, true);
          continue;
        }
        if (verdict != BlobCheck::kAccepted) {
          ++stats.rejected_size;
          leave(part.blob, verdict == BlobCheck::kTooSmall ? "narrower than perception.min_sherd_size"
                                                           : "longer than perception.max_sherd_size");
          continue;
        }
      }
      SherdDetection d;
      std::string why;
      if (!measurer_.measure(part.blob, rgb, depth_mm, view, r.plane, d, why)) {
        ++r.rejected_size;
        if (!depth_mm.empty()) leave(part.blob, why, &d);
        continue;
      }
      d.covered = part.covered;
      d.support = part.support;
      const double own = d.height - d.support;
      if (own > d.width && own >= kStandingHeight * config_.min_sherd_size) {
        // standing up from what it rests on (on a station: set down hanging from the fingers by
        // its lower edge); grasped it is held by its foot, or missed: the task layer topples it
        leave(part.blob, "standing " + std::to_string(static_cast<int>(own * 1000)) +
                             " mm tall from what it rests on, taller than wide: standing on its edge?",
              &d);
        continue;
      }
      GraspContext around;
      around.height = &height;
      around.view = &view;
      around.own = &part.blob;
      planner_.plan(d, &around);
      r.sherds.push_back(std::move(d));
      offered.push_back(part.blob);
      group.push_back(static_cast<int>(blob));
    }
  }
  {
    // and under the edge of a neighbour the segmenter cut apart from it
    std::vector<const Blob*> outlines;
    std::vector<double> walls;
    for (size_t k = 0; k < r.sherds.size(); ++k) {
      outlines.push_back(&offered[k]);
      walls.push_back(r.sherds[k].thickness);
    }
    const std::vector<double> across = StackSplitter::coveredAcross(outlines, group, walls, height, stack);
    for (size_t k = 0; k < r.sherds.size(); ++k) r.sherds[k].covered += across[k];
  }
  r.rejected_border = stats.rejected_border;
  r.rejected_size += stats.rejected_size;
  planner_.score(r.sherds);
  // best score first, ties in segmentation order; which sherd is picked is the task layer's choice
  std::stable_sort(r.sherds.begin(), r.sherds.end(),
                   [](const SherdDetection& a, const SherdDetection& b) { return a.score > b.score; });
  r.success = true;
  r.message = "station " + station + ": " + std::to_string(r.sherds.size()) + " sherds";
  return r;
}

}  // namespace rascal_perception
