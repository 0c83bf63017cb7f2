#include "rascal_sim/SurfaceRealism.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace rascal_sim {

namespace {
constexpr int kFixtures = 1;        // World::renderItems: the table and its fixtures
constexpr int kFirstSherd = 10;     // World::renderItems: sherd i has label 10 + i
constexpr double kShininess = 40.0; // Blinn-Phong exponent: a broad glaze highlight
constexpr double kMinShadowHeight = 0.001;  // [m] points this low cast no visible shadow

/// Texture value at world (x, y) [m], tiled by mirroring so no seam shows.
float sample(const cv::Mat& tex, double x, double y) {
  auto mirror = [](long i, int n) {
    const long period = 2L * n;
    long m = ((i % period) + period) % period;
    return static_cast<int>(m < n ? m : period - 1 - m);
  };
  const long u = std::lround(x * SurfaceRealism::kTexturePxPerMetre);
  const long v = std::lround(y * SurfaceRealism::kTexturePxPerMetre);
  return tex.at<float>(mirror(v, tex.rows), mirror(u, tex.cols));
}
}  // namespace

void SurfaceRealism::load(const std::string& data_dir) {
  cloth_.clear();
  sherd_.clear();
  for (const char* kind : {"cloth", "sherd"}) {
    for (int i = 1; i <= 9; ++i) {
      const std::string file = data_dir + "/textures/" + kind + "_" + std::to_string(i) + ".png";
      if (!std::filesystem::exists(file)) break;
      const cv::Mat grey = cv::imread(file, cv::IMREAD_GRAYSCALE);
      if (grey.empty()) throw std::runtime_error("cannot read the texture " + file);
      cv::Mat f;
      grey.convertTo(f, CV_32F, 1.0 / 128.0);  // stored with 128 = the crop's own shading
      (std::string(kind) == "cloth" ? cloth_ : sherd_).push_back(f);
    }
  }
  if (!loaded()) throw std::runtime_error("no surface textures in " + data_dir + "/textures (cloth_1.png, sherd_1.png)");
}

void SurfaceRealism::apply(cv::Mat& colour, const RenderOutput& r, const CameraModel& cam,
                           const Eigen::Isometry3d& world_T_camera, const Realism& realism) const {
  if (!realism.any() || !loaded()) return;
  const Eigen::Isometry3d camera_T_world = world_T_camera.inverse();
  // direction towards the light, in the world and in the camera
  const Eigen::Vector3d to_light(std::cos(realism.light_elevation) * std::cos(realism.light_azimuth),
                                 std::cos(realism.light_elevation) * std::sin(realism.light_azimuth),
                                 std::sin(realism.light_elevation));
  const Eigen::Vector3d light_cam = camera_T_world.linear() * to_light;
  // a point h above the table throws its shadow h / tan(elevation) away from the light
  const Eigen::Vector2d shadow_step = -to_light.head<2>() / std::max(1e-3, to_light.z());

  cv::Mat points(r.depth.size(), CV_32FC3, cv::Scalar::all(0));  // camera frame [m]
  for (int y = 0; y < r.depth.rows; ++y) {
    const float* d = r.depth.ptr<float>(y);
    cv::Vec3f* p = points.ptr<cv::Vec3f>(y);
    for (int x = 0; x < r.depth.cols; ++x) {
      if (d[x] > 0.0f) {
        p[x] = cv::Vec3f(static_cast<float>((x - cam.cx) / cam.fx * d[x]), static_cast<float>((y - cam.cy) / cam.fy * d[x]),
                         d[x]);
      }
    }
  }
  cv::Mat shadow = cv::Mat::zeros(r.depth.size(), CV_8U);
  cv::Mat gain(r.depth.size(), CV_32F, cv::Scalar(1.0f));
  cv::Mat highlight = cv::Mat::zeros(r.depth.size(), CV_32F);
  for (int y = 1; y + 1 < r.depth.rows; ++y) {
    const uint16_t* label = r.label.ptr<uint16_t>(y);
    const cv::Vec3f* p = points.ptr<cv::Vec3f>(y);
    float* g = gain.ptr<float>(y);
    float* h = highlight.ptr<float>(y);
    for (int x = 1; x + 1 < r.depth.cols; ++x) {
      const int id = label[x];
      if (p[x][2] <= 0.0f || (id != kFixtures && id < kFirstSherd)) continue;  // nothing, or the arm
      const Eigen::Vector3d pc(p[x][0], p[x][1], p[x][2]);
      const Eigen::Vector3d w = world_T_camera * pc;
      if (id == kFixtures) {
        if (w.z() < kTableTop) g[x] = 1.0f + static_cast<float>(realism.texture) * (sample(cloth_[0], w.x(), w.y()) - 1.0f);
        continue;
      }
      // a sherd: its own texture (shifted per sherd so neighbours differ), its shadow, its gloss
      const int k = id - kFirstSherd;
      const cv::Mat& tex = sherd_[static_cast<size_t>(k) % sherd_.size()];
      g[x] = 1.0f + static_cast<float>(realism.texture) * (sample(tex, w.x() + 0.013 * k, w.y() - 0.007 * k) - 1.0f);
      if (realism.cast_shadow > 0.0 && w.z() > kMinShadowHeight) {
        const Eigen::Vector3d s(w.x() + w.z() * shadow_step.x(), w.y() + w.z() * shadow_step.y(), 0.0);
        const Eigen::Vector3d sc = camera_T_world * s;
        if (sc.z() > 1e-3) {
          const Eigen::Vector2d uv = cam.project(sc);
          const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
          if (u >= 0 && v >= 0 && u < shadow.cols && v < shadow.rows) shadow.at<uint8_t>(v, u) = 255;
        }
      }
      if (realism.glare > 0.0) {
        // the facet's normal from the neighbouring points (flat shading: one per triangle)
        const cv::Vec3f dx = points.at<cv::Vec3f>(y, x + 1) - points.at<cv::Vec3f>(y, x - 1);
        const cv::Vec3f dy = points.at<cv::Vec3f>(y + 1, x) - points.at<cv::Vec3f>(y - 1, x);
        if (points.at<cv::Vec3f>(y, x + 1)[2] <= 0.0f || points.at<cv::Vec3f>(y + 1, x)[2] <= 0.0f ||
            points.at<cv::Vec3f>(y, x - 1)[2] <= 0.0f || points.at<cv::Vec3f>(y - 1, x)[2] <= 0.0f) {
          continue;
        }
        Eigen::Vector3d n = Eigen::Vector3d(dx[0], dx[1], dx[2]).cross(Eigen::Vector3d(dy[0], dy[1], dy[2]));
        if (n.norm() < 1e-12) continue;
        n.normalize();
        if (n.dot(pc) > 0) n = -n;  // facing the camera
        const Eigen::Vector3d half = (light_cam - pc.normalized()).normalized();
        h[x] = static_cast<float>(realism.glare * std::pow(std::max(0.0, n.dot(half)), kShininess));
      }
    }
  }
  if (realism.cast_shadow > 0.0) {
    // the scattered shadow points: closed into a shape, then a soft penumbra
    const int grow = std::max(3, static_cast<int>(std::lround(0.002 * cam.fx / 0.25)) | 1);
    cv::dilate(shadow, shadow, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(grow, grow)));
    cv::GaussianBlur(shadow, shadow, cv::Size(0, 0), 0.5 * grow);
  }
  for (int y = 0; y < colour.rows; ++y) {
    cv::Vec3b* c = colour.ptr<cv::Vec3b>(y);
    const uint16_t* label = r.label.ptr<uint16_t>(y);
    const float* g = gain.ptr<float>(y);
    const float* h = highlight.ptr<float>(y);
    const uint8_t* s = shadow.ptr<uint8_t>(y);
    for (int x = 0; x < colour.cols; ++x) {
      // textures were measured as ratios of sRGB codes; light (shadow, gloss) adds up linearly
      const float light = label[x] == kFixtures ? 1.0f - static_cast<float>(realism.cast_shadow) * s[x] / 255.0f : 1.0f;
      for (int ch = 0; ch < 3; ++ch) {
        const uint8_t textured = cv::saturate_cast<uint8_t>(c[x][ch] * g[x]);
        c[x][ch] = Renderer::encodeSrgb(Renderer::decodeSrgb(textured) * light + h[x]);
      }
    }
  }
}

}  // namespace rascal_sim
