#include "rascal_sim/SensorEffects.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rascal_sim/Mesh.hpp"
#include "rascal_sim/Renderer.hpp"

namespace rascal_sim {

namespace {
constexpr size_t kGaussTable = 1 << 21;
constexpr double kDepthCx = 319.0;  // [px] D435 depth at 640 x 480 (facts §4.3)
constexpr double kShadowPeriod = 60.0;  // [s] the shadow's path repeats

}  // namespace

SensorEffects::SensorEffects(unsigned seed) : rng_(seed), gauss_(kGaussTable) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (auto& g : gauss_) g = n(rng_);
}

Eigen::Vector3d SensorEffects::temperatureGains(double kelvin) {
  // Approximate sRGB colour of black-body light (D65 white), every 500 K from 2500 to 10000 K.
  static const double table[][3] = {
      {1.00, 0.62, 0.30}, {1.00, 0.69, 0.42}, {1.00, 0.75, 0.53}, {1.00, 0.80, 0.63},
      {1.00, 0.85, 0.72}, {1.00, 0.89, 0.80}, {1.00, 0.93, 0.87}, {1.00, 0.96, 0.94},
      {1.00, 0.99, 1.00}, {0.95, 0.96, 1.00}, {0.92, 0.94, 1.00}, {0.89, 0.92, 1.00},
      {0.86, 0.905, 1.00}, {0.84, 0.89, 1.00}, {0.82, 0.875, 1.00}, {0.80, 0.86, 1.00}};
  const double k = std::min(10000.0, std::max(2500.0, kelvin));
  const double f = (k - 2500.0) / 500.0;
  const int i = std::min(14, static_cast<int>(f));
  const double s = f - i;
  Eigen::Vector3d c, ref(table[8][0], table[8][1], table[8][2]);
  for (int j = 0; j < 3; ++j) c[j] = table[i][j] * (1 - s) + table[i + 1][j] * s;
  const Eigen::Vector3f lin = Mesh::srgbToLinear(c), lin_ref = Mesh::srgbToLinear(ref);
  Eigen::Vector3d g(lin.x() / lin_ref.x(), lin.y() / lin_ref.y(), lin.z() / lin_ref.z());
  return g / (0.2126 * g.x() + 0.7152 * g.y() + 0.0722 * g.z());
}

Eigen::Vector3f SensorEffects::lightGain(const Lighting& lighting) {
  return (temperatureGains(lighting.colour_temperature) * lighting.brightness).cast<float>();
}

void SensorEffects::colourImage(cv::Mat& img, const cv::Mat& depth, const CameraModel& cam,
                                const Eigen::Isometry3d& world_T_camera, const Lighting& lighting,
                                double t, double blur_px) {
  const Eigen::Vector2d centre = lighting.shadow_start + lighting.shadow_velocity * std::fmod(t, kShadowPeriod);
  const double r_out = lighting.shadow_radius;
  if (lighting.shadow_strength > 0.0) {
    // image box of the shadow disc (table level up to 5 cm above it)
    const Eigen::Isometry3d camera_T_world = world_T_camera.inverse();
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    bool behind = false;
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d w(centre.x() + ((i & 1) ? r_out : -r_out), centre.y() + ((i & 2) ? r_out : -r_out),
                              (i & 4) ? 0.05 : 0.0);
      const Eigen::Vector3d c = camera_T_world * w;
      if (c.z() < 1e-3) {
        behind = true;
        break;
      }
      const Eigen::Vector2d uv = cam.project(c);
      u0 = std::min(u0, uv.x());
      u1 = std::max(u1, uv.x());
      v0 = std::min(v0, uv.y());
      v1 = std::max(v1, uv.y());
    }
    const int xa = behind ? 0 : std::max(0, static_cast<int>(u0));
    const int xb = behind ? cam.width - 1 : std::min(cam.width - 1, static_cast<int>(u1) + 1);
    const int ya = behind ? 0 : std::max(0, static_cast<int>(v0));
    const int yb = behind ? cam.height - 1 : std::min(cam.height - 1, static_cast<int>(v1) + 1);
    const float ro = static_cast<float>(r_out), ri = 0.6f * ro, ro2 = ro * ro;
    const float strength = static_cast<float>(lighting.shadow_strength);
    const Eigen::Matrix3d R = world_T_camera.linear();
    const Eigen::Vector3d p0 = world_T_camera.translation();
    const Eigen::Vector3d dx = R.col(0) / cam.fx;  // world ray of pixel (x, y) = row(y) + x * dx
    const float dxx = static_cast<float>(dx.x()), dxy = static_cast<float>(dx.y());
    const float cx0 = static_cast<float>(p0.x() - centre.x()), cy0 = static_cast<float>(p0.y() - centre.y());
    for (int y = ya; y <= yb; ++y) {
      const float* drow = depth.ptr<float>(y);
      cv::Vec3b* row_px = img.ptr<cv::Vec3b>(y);
      const Eigen::Vector3d row = R * Eigen::Vector3d(-cam.cx / cam.fx, (y - cam.cy) / cam.fy, 1.0);
      const float rx = static_cast<float>(row.x()), ry = static_cast<float>(row.y());
      for (int x = xa; x <= xb; ++x) {
        const float z = drow[x];
        if (z <= 0.0f) continue;
        const float wx = cx0 + z * (rx + x * dxx), wy = cy0 + z * (ry + x * dxy);
        const float d2 = wx * wx + wy * wy;
        if (d2 >= ro2) continue;
        const float d = std::sqrt(d2);
        const float s = d <= ri ? 1.0f : (ro - d) / (ro - ri);
        const float f = 1.0f - strength * s * s * (3.0f - 2.0f * s);
        cv::Vec3b& px = row_px[x];
        for (int c = 0; c < 3; ++c) px[c] = Renderer::encodeSrgb(Renderer::decodeSrgb(px[c]) * f);
      }
    }
  }
  if (blur_px >= 1.5) {
    const int k = std::min(31, static_cast<int>(std::lround(blur_px)) | 1);
    cv::blur(img, img, cv::Size(k, k));
  }
  const float sigma = static_cast<float>(lighting.colour_noise);
  if (sigma > 0) {
    if (noise_sigma_ != sigma) {
      noise_sigma_ = sigma;
      noise_.resize(gauss_.size());
      for (size_t i = 0; i < gauss_.size(); ++i) {
        noise_[i] = static_cast<int16_t>(std::lround(std::max(-127.0f, std::min(127.0f, sigma * gauss_[i]))));
      }
    }
    uint8_t* p = img.ptr<uint8_t>(0);
    const size_t n = img.total() * 3;
    // a contiguous window of the table at a random offset (vectorises)
    const int16_t* nz = noise_.data() + (n < kGaussTable ? rng_() % (kGaussTable - n) : 0);
    for (size_t i = 0; i < std::min(n, kGaussTable); ++i) {
      const int v = p[i] + nz[i];
      p[i] = static_cast<uint8_t>(v < 0 ? 0 : (v > 255 ? 255 : v));
    }
  }
}

void SensorEffects::archivalCamera(cv::Mat& img, const CameraModel& cam) {
  // tone: code -> code after the S-curve (monotone: slope 1 - c cos(2 pi v) > 0)
  uint8_t tone[256];
  for (int i = 0; i < 256; ++i) {
    const double v = i / 255.0;
    const double t = v - kToneContrast * std::sin(2.0 * M_PI * v) / (2.0 * M_PI);
    tone[i] = static_cast<uint8_t>(std::lround(255.0 * std::min(1.0, std::max(0.0, t))));
  }
  for (int y = 0; y < img.rows; ++y) {
    cv::Vec3b* row = img.ptr<cv::Vec3b>(y);
    const double ty = (y - cam.cy) / cam.fy;
    for (int x = 0; x < img.cols; ++x) {
      const double tx = (x - cam.cx) / cam.fx;
      const double c2 = 1.0 / (1.0 + tx * tx + ty * ty);  // cos^2 of the field angle
      const float falloff = static_cast<float>(c2 * c2);
      for (int c = 0; c < 3; ++c) row[x][c] = tone[Renderer::encodeSrgb(Renderer::decodeSrgb(row[x][c]) * falloff)];
    }
  }
  std::vector<uint8_t> jpeg;
  cv::Mat bgr;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);  // the renderer's images are RGB
  cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, kJpegQuality});
  cv::cvtColor(cv::imdecode(jpeg, cv::IMREAD_COLOR), img, cv::COLOR_BGR2RGB);
}

cv::Mat SensorEffects::depthImage(const cv::Mat& depth, const CameraModel& cam, bool left_band) {
  cv::Mat out(cam.height, cam.width, CV_16UC1);
  const size_t total = static_cast<size_t>(cam.width) * cam.height;
  const float* g = gauss_.data() + (total < kGaussTable ? rng_() % (kGaussTable - total) : 0);
  // left invalid band: seen by the left imager only, f*B/Z depth pixels wide;
  // column x is inside it when z * band[x] < f*B
  std::vector<float> band(cam.width);
  for (int x = 0; x < cam.width; ++x) {
    band[x] = left_band ? static_cast<float>(kDepthFocal * (x - cam.cx) / cam.fx + kDepthCx) : 1e9f;
  }
  const float fb = static_cast<float>(kDepthFocal * kBaseline);
  const float noise_k = static_cast<float>(kSubpixelSigma / (kDepthFocal * kBaseline));
  const float zmin = static_cast<float>(kMinDepth);
  for (int y = 0; y < cam.height; ++y) {
    const float* d = depth.ptr<float>(y);
    uint16_t* o = out.ptr<uint16_t>(y);
    for (int x = 0; x < cam.width; ++x) {
      const float z = d[x];
      if (z < zmin || z * band[x] < fb) {
        o[x] = 0;
        continue;
      }
      const float zn = z + z * z * noise_k * g[static_cast<size_t>(y) * cam.width + x];
      const float mm = zn * 1000.0f + 0.5f;
      o[x] = static_cast<uint16_t>(mm < 0.0f ? 0.0f : (mm > 65535.0f ? 65535.0f : mm));
    }
  }
  return out;
}

}  // namespace rascal_sim
