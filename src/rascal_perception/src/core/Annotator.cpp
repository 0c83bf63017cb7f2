#include "rascal_perception/Annotator.hpp"

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace rascal_perception {

cv::Mat Annotator::draw(const cv::Mat& rgb, const std::vector<SherdDetection>& sherds, const cv::Mat& fixture,
                        const CameraView* view) {
  cv::Mat out = rgb.clone();
  if (!fixture.empty() && fixture.size() == rgb.size()) {
    cv::Mat shade = out.clone();
    shade.setTo(cv::Scalar(90, 90, 90), fixture);
    cv::addWeighted(out, 0.5, shade, 0.5, 0.0, out);
  }
  const double scale = std::max(0.4, rgb.cols / 1600.0);
  const int thick = std::max(1, static_cast<int>(std::lround(rgb.cols / 640.0)));
  for (size_t i = 0; i < sherds.size(); ++i) {
    const SherdDetection& s = sherds[i];
    const cv::Scalar colour = i == 0 ? cv::Scalar(255, 40, 40) : cv::Scalar(40, 255, 40);
    if (!s.contour.empty()) {
      cv::drawContours(out, std::vector<std::vector<cv::Point>>{s.contour}, 0, cv::Scalar(255, 255, 0), thick);
    }
    const float a = s.image_box[4];
    const cv::Point2f u(std::cos(a), std::sin(a)), w(-std::sin(a), std::cos(a));
    const cv::Point2f m(s.image_box[0], s.image_box[1]);
    const float hl = 0.5f * s.image_box[2], hw = 0.5f * s.image_box[3];
    const cv::Point2f c[4] = {m + hl * u + hw * w, m - hl * u + hw * w, m - hl * u - hw * w, m + hl * u - hw * w};
    for (int k = 0; k < 4; ++k) cv::line(out, c[k], c[(k + 1) % 4], colour, thick, cv::LINE_AA);
    // the fingers close across the minor axis
    const cv::Point2f centre(s.image_box[0], s.image_box[1]);
    const cv::Point2f across(-std::sin(a), std::cos(a));
    const float half = 0.5f * s.image_box[3] * 1.3f;
    cv::Point2f f0 = centre - half * across, f1 = centre + half * across;
    if (view) {
      const Eigen::Isometry3d cam_T_base = view->base_T_camera.inverse();
      const Eigen::Vector3d mid(s.grasp.translation().x(), s.grasp.translation().y(), s.centre.z());
      const Eigen::Vector3d side = s.grasp.linear().col(1) * (0.5 * s.grasp_width);
      const Eigen::Vector3d p0 = cam_T_base * (mid - side), p1 = cam_T_base * (mid + side);
      if (p0.z() > 0 && p1.z() > 0) {
        const Eigen::Vector2d a0 = view->intrinsics.project(p0), a1 = view->intrinsics.project(p1);
        f0 = cv::Point2f(static_cast<float>(a0.x()), static_cast<float>(a0.y()));
        f1 = cv::Point2f(static_cast<float>(a1.x()), static_cast<float>(a1.y()));
      }
    }
    cv::line(out, f0, f1, cv::Scalar(255, 0, 255), thick, cv::LINE_AA);
    char label[96];
    if (s.length > 0) {
      std::snprintf(label, sizeof(label), "#%zu %.0fx%.0f mm h%.1f", i, s.length * 1e3, s.width * 1e3, s.height * 1e3);
    } else {
      std::snprintf(label, sizeof(label), "#%zu", i);
    }
    cv::putText(out, label, centre + cv::Point2f(-0.5f * s.image_box[2], -0.5f * s.image_box[2] - 4.0f),
                cv::FONT_HERSHEY_SIMPLEX, scale, colour, thick, cv::LINE_AA);
  }
  return out;
}

}  // namespace rascal_perception
