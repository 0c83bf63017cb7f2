#include "rascal_perception/SherdMeasurer.hpp"

#include "rascal_perception/ShellFit.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace rascal_perception {

namespace {
constexpr double kMinPointHeight = 0.0015;  ///< [m] lower points belong to the table (noise, edges)
/// [px] depth pixels nearer the outline than this mix the sherd's depth with the table's (the
/// D435's flying pixels at edges): they are left out of the shell fit (ShellFit).
constexpr float kInteriorMargin = 3.0f;
/// [mm] in the table plane, samples nearer the footprint's edge than this are left out of the
/// shell fit too (side walls, below).
constexpr float kWallMarginMm = 1.5f;

double planeZ(const Eigen::Vector4d& plane, double x, double y) {
  return -(plane.x() * x + plane.y() * y + plane.w()) / plane.z();
}
}  // namespace

cv::Mat SherdMeasurer::rayZMap(const CameraView& view) {
  const CameraIntrinsics& k = view.intrinsics;
  cv::Mat map(k.height, k.width, CV_32F);
  const Eigen::Vector3d r2 = view.base_T_camera.linear().row(2);
  for (int y = 0; y < k.height; ++y) {
    float* m = map.ptr<float>(y);
    for (int x = 0; x < k.width; ++x) m[x] = static_cast<float>(r2.dot(k.ray(x, y)));
  }
  return map;
}

PlaneFit SherdMeasurer::fitPlane(const cv::Mat& depth_mm, const cv::Mat& usable, const CameraView& view,
                                 double surface_z) const {
  const CameraIntrinsics& k = view.intrinsics;
  const Eigen::Isometry3f pose = view.base_T_camera.cast<float>();
  std::vector<Eigen::Vector3f> points;
  const int step = 6;
  const uint16_t lo = static_cast<uint16_t>(config_.depth_min * 1000.0);
  const uint16_t hi = static_cast<uint16_t>(std::min(65535.0, config_.depth_max * 1000.0));
  for (int y = step / 2; y < depth_mm.rows; y += step) {
    const uint16_t* d = depth_mm.ptr<uint16_t>(y);
    const uint8_t* u = usable.empty() ? nullptr : usable.ptr<uint8_t>(y);
    for (int x = step / 2; x < depth_mm.cols; x += step) {
      if (d[x] < lo || d[x] > hi || (u && !u[x])) continue;
      const float z = d[x] * 0.001f;
      const Eigen::Vector3f p =
          pose * Eigen::Vector3f(static_cast<float>((x - k.cx) / k.fx) * z, static_cast<float>((y - k.cy) / k.fy) * z, z);
      if (std::fabs(p.z() - surface_z) < 0.015) points.push_back(p);
    }
  }
  PlaneFit fit = TablePlane::fit(points, config_.plane_tolerance);
  if (!fit.ok) fit.plane = Eigen::Vector4d(0, 0, 1, -surface_z);
  return fit;
}

bool SherdMeasurer::intersect(const CameraView& view, const Eigen::Vector4d& plane, double height, double u,
                              double v, Eigen::Vector3d& point) {
  const Eigen::Vector3d o = view.base_T_camera.translation();
  const Eigen::Vector3d w = view.base_T_camera.linear() * view.intrinsics.ray(u, v);
  const Eigen::Vector3d n = plane.head<3>();
  const double denom = n.dot(w);
  if (std::fabs(denom) < 1e-9) return false;
  const double t = (height - plane.w() - n.dot(o)) / denom;
  if (t <= 0) return false;
  point = o + t * w;
  return true;
}

bool SherdMeasurer::measure(const Blob& blob, const cv::Mat& rgb, const cv::Mat& depth_mm, const CameraView& view,
                            const Eigen::Vector4d& plane, SherdDetection& out, std::string& why) const {
  const CameraIntrinsics& k = view.intrinsics;
  const Eigen::Vector3d n = plane.head<3>();
  const uint16_t dmin = static_cast<uint16_t>(config_.depth_min * 1000.0);
  const uint16_t dmax = static_cast<uint16_t>(std::min(65535.0, config_.depth_max * 1000.0));
  std::vector<cv::Point2f> footprint;  // [mm] in the plane, base_link x, y
  std::vector<float> heights;
  std::vector<TopSample> top_surface;
  footprint.reserve(blob.pixels);
  heights.reserve(blob.pixels);
  top_surface.reserve(blob.pixels);
  cv::Mat inside;  // [px] to the outline (the mask padded: its box's edge is outside too)
  {
    cv::Mat padded;
    cv::copyMakeBorder(blob.mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::distanceTransform(padded, inside, cv::DIST_L2, 3);
  }
  cv::Vec3d colour(0, 0, 0);
  int coloured = 0;
  for (int y = 0; y < blob.mask.rows; ++y) {
    const uint8_t* m = blob.mask.ptr<uint8_t>(y);
    const int iy = y + blob.bounds.y;
    const uint16_t* d = depth_mm.empty() ? nullptr : depth_mm.ptr<uint16_t>(iy);
    const cv::Vec3b* c = rgb.ptr<cv::Vec3b>(iy);
    for (int x = 0; x < blob.mask.cols; ++x) {
      if (!m[x]) continue;
      const int ix = x + blob.bounds.x;
      colour += cv::Vec3d(c[ix][0], c[ix][1], c[ix][2]);
      ++coloured;
      if (!d || d[ix] < dmin || d[ix] > dmax) continue;
      const double z = d[ix] * 0.001;
      const Eigen::Vector3d p = view.base_T_camera * (k.ray(ix, iy) * z);
      const double h = n.dot(p) + plane.w();
      if (h < kMinPointHeight) continue;
      const Eigen::Vector3d q = p - h * n;
      footprint.emplace_back(static_cast<float>(q.x() * 1000.0), static_cast<float>(q.y() * 1000.0));
      heights.push_back(static_cast<float>(h));
      top_surface.push_back({q.x(), q.y(), h, inside.at<float>(y + 1, x + 1) > kInteriorMargin});
    }
  }
  out = SherdDetection();
  if (coloured > 0) out.colour = Eigen::Vector3d(colour[0], colour[1], colour[2]) / (255.0 * coloured);
  out.depth_valid = static_cast<int>(heights.size()) >= std::max(20, blob.pixels * 3 / 10);
  if (out.depth_valid) {
    const size_t i95 = heights.size() * 95 / 100;
    std::nth_element(heights.begin(), heights.begin() + i95, heights.end());
    out.height = heights[i95];
  } else {
    footprint.clear();
  }
  // the outline: the image contour on the plane raised to the top surface
  std::vector<cv::Point> poly;
  cv::approxPolyDP(blob.contour, poly, 1.0, true);
  std::vector<cv::Point2f> outline_mm;
  for (const cv::Point& p : poly) {
    Eigen::Vector3d q;
    if (!intersect(view, plane, out.height, p.x, p.y, q)) continue;
    outline_mm.emplace_back(static_cast<float>(q.x() * 1000.0), static_cast<float>(q.y() * 1000.0));
    out.outline.emplace_back(q.x(), q.y(), planeZ(plane, q.x(), q.y()));
  }
  if (outline_mm.size() < 3) {
    why = "its outline does not meet the table plane";
    return false;
  }
  out.area = cv::contourArea(outline_mm) * 1e-6;
  if (!out.depth_valid) {  // no depth: the contour on the plane gives the footprint
    for (const cv::Point& p : blob.contour) {
      Eigen::Vector3d q;
      if (intersect(view, plane, 0.0, p.x, p.y, q)) {
        footprint.emplace_back(static_cast<float>(q.x() * 1000.0), static_cast<float>(q.y() * 1000.0));
      }
    }
  }
  if (footprint.size() < 3) {
    why = "too few points on its top surface";
    return false;
  }
  // Axes from the second moments of the footprint's area (minAreaRect's orientation is unstable
  // for rounded outlines, and the visible side walls would weigh the points on one side): the
  // footprint points are drawn into a 0.25 mm top-view raster, closed and filled first.
  cv::Point2f lo(1e9f, 1e9f), hi(-1e9f, -1e9f);
  for (const cv::Point2f& p : footprint) {
    lo.x = std::min(lo.x, p.x), lo.y = std::min(lo.y, p.y), hi.x = std::max(hi.x, p.x), hi.y = std::max(hi.y, p.y);
  }
  constexpr float kCell = 0.25f;  // [mm]
  const int pad = 8;
  cv::Mat top = cv::Mat::zeros(static_cast<int>((hi.y - lo.y) / kCell) + 2 * pad + 1,
                               static_cast<int>((hi.x - lo.x) / kCell) + 2 * pad + 1, CV_8U);
  for (const cv::Point2f& p : footprint) {
    top.at<uint8_t>(static_cast<int>((p.y - lo.y) / kCell) + pad, static_cast<int>((p.x - lo.x) / kCell) + pad) = 255;
  }
  const double range0 = n.dot(view.base_T_camera.translation()) + plane.w() - out.height;
  // two pixels' footprint on the plane, and never under 5 cells: at 3 a close view's pixels (1.4 cells
  // apart at 0.22 m) left gaps the 3 x 3 cross did not fill, and no sample counted as interior
  const int gap = std::max(5, static_cast<int>(std::ceil(2.0 * range0 / k.fx * 1000.0 / kCell)) | 1);
  cv::morphologyEx(top, top, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(gap, gap)));
  if (out.depth_valid) {
    // The shell fit takes only the top face: a sherd's side wall, seen obliquely away from the
    // image centre (up to ~15 px for a 15 mm sherd 0.15 m off the axis at 0.3 m), stands on
    // its outline in the table plane, so samples near the footprint's edge there are left out.
    cv::Mat edge;
    cv::distanceTransform(top, edge, cv::DIST_L2, 3);
    for (TopSample& t : top_surface) {
      const int r = static_cast<int>((t.y * 1000.0 - lo.y) / kCell) + pad;
      const int c = static_cast<int>((t.x * 1000.0 - lo.x) / kCell) + pad;
      t.interior = t.interior && edge.at<float>(r, c) * kCell >= kWallMarginMm;
    }
    const ShellFit shell = ShellFit::estimate(top_surface);
    out.thickness = shell.valid ? shell.thickness : 0.0;
    out.thickness_why = shell.why;
    out.diameter = shell.diameter;
    out.diameter_sigma = shell.diameter_sigma;
    out.diameter_why = shell.diameter_why;
  }
  const cv::Moments mo = cv::moments(top, true);
  if (mo.m00 <= 0) {
    why = "empty footprint";
    return false;
  }
  const cv::Point2d mean(lo.x + (mo.m10 / mo.m00 - pad) * kCell, lo.y + (mo.m01 / mo.m00 - pad) * kCell);
  const double theta = 0.5 * std::atan2(2.0 * mo.mu11, mo.mu20 - mo.mu02);
  const double ca = std::cos(theta), sa = std::sin(theta);
  double u0 = 1e18, u1 = -1e18, v0 = 1e18, v1 = -1e18;
  for (const cv::Point2f& p : footprint) {
    const double dx = p.x - mean.x, dy = p.y - mean.y;
    const double u = ca * dx + sa * dy, v = -sa * dx + ca * dy;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, v), v1 = std::max(v1, v);
  }
  // depth samples sit at pixel centres: half a pixel of the top surface is missing at each side
  const double range = n.dot(view.base_T_camera.translation()) + plane.w() - out.height;
  const double half_px = out.depth_valid ? 0.5 * range / k.fx * 1000.0 : 0.0;
  double major = u1 - u0 + 2 * half_px, minor = v1 - v0 + 2 * half_px, yaw = theta;
  if (minor > major) {
    std::swap(major, minor);
    yaw += M_PI / 2;
  }
  out.length = major * 1e-3;
  out.width = minor * 1e-3;
  out.yaw = wrapHalfPi(yaw);
  const double mu = 0.5 * (u0 + u1), mv = 0.5 * (v0 + v1);
  const double cx = (mean.x + ca * mu - sa * mv) * 1e-3, cy = (mean.y + sa * mu + ca * mv) * 1e-3;
  out.surface = planeZ(plane, cx, cy);
  out.centre = Eigen::Vector3d(cx, cy, out.surface + out.height / n.z());
  if (out.width < config_.min_sherd_size) {
    // seen from above, a sherd standing on its edge (leaning in a heap) is a strip taller than wide
    why = out.height > out.width ? "narrower than perception.min_sherd_size seen from above and taller than wide: "
                                   "standing on its edge? lay it flat"
                                 : "narrower than perception.min_sherd_size";
    return false;
  }
  if (out.length > config_.max_sherd_size) {
    why = "longer than perception.max_sherd_size";
    return false;
  }
  // the colour-image box: its long side's direction from its corners (no angle convention)
  const cv::RotatedRect& b = blob.box;
  cv::Point2f q[4];
  b.points(q);
  const cv::Point2f s1 = q[1] - q[0], s2 = q[2] - q[1];
  const double n1 = std::hypot(s1.x, s1.y), n2 = std::hypot(s2.x, s2.y);
  const cv::Point2f along = n1 >= n2 ? s1 : s2;
  out.image_box[0] = b.center.x;
  out.image_box[1] = b.center.y;
  out.image_box[2] = static_cast<float>(std::max(n1, n2));
  out.image_box[3] = static_cast<float>(std::min(n1, n2));
  out.image_box[4] = static_cast<float>(wrapHalfPi(std::atan2(along.y, along.x)));
  out.contour = blob.contour;
  return true;
}

}  // namespace rascal_perception
