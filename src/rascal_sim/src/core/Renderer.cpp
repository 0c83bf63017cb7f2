#include "rascal_sim/Renderer.hpp"

#include <algorithm>
#include <cmath>

namespace rascal_sim {

namespace {
struct ClipVertex {
  Eigen::Vector3d p;  // camera frame
};

struct Target {
  cv::Mat* colour;
  cv::Mat* depth;
  cv::Mat* label;
};

void rasterTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const CameraModel& cam, const cv::Vec3b& col, int id, Target& t) {
  const double ua = cam.fx * a.x() / a.z() + cam.cx, va = cam.fy * a.y() / a.z() + cam.cy;
  const double ub = cam.fx * b.x() / b.z() + cam.cx, vb = cam.fy * b.y() / b.z() + cam.cy;
  const double uc = cam.fx * c.x() / c.z() + cam.cx, vc = cam.fy * c.y() / c.z() + cam.cy;
  const double area = (ub - ua) * (vc - va) - (vb - va) * (uc - ua);
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ua, ub, uc}))));
  const int x1 = std::min(cam.width - 1, static_cast<int>(std::floor(std::max({ua, ub, uc}))));
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({va, vb, vc}))));
  const int y1 = std::min(cam.height - 1, static_cast<int>(std::floor(std::max({va, vb, vc}))));
  if (x0 > x1 || y0 > y1) return;
  const double inv_area = 1.0 / area;
  const double iza = 1.0 / a.z(), izb = 1.0 / b.z(), izc = 1.0 / c.z();
  // barycentric weights w0 (of a), w1 (of b), w2 = 1 - w0 - w1 as affine functions of (x, y)
  const double w0x = (vb - vc) * inv_area, w0y = (uc - ub) * inv_area;
  const double w1x = (vc - va) * inv_area, w1y = (ua - uc) * inv_area;
  const double w0o = (ub * vc - vb * uc) * inv_area;  // value at (0, 0)
  const double w1o = (uc * va - vc * ua) * inv_area;
  const double izx = w0x * iza + w1x * izb - (w0x + w1x) * izc;
  const uint16_t lid = static_cast<uint16_t>(id);
  const double eps = 1e-9;
  for (int y = y0; y <= y1; ++y) {
    // span of x where all three weights are >= 0 on this row
    const double a0 = w0o + w0y * y, a1 = w1o + w1y * y;
    const double a2 = 1.0 - a0 - a1, b2 = -(w0x + w1x);
    double lo = x0, hi = x1;
    bool empty = false;
    auto limit = [&](double a, double b) {
      if (std::abs(b) < 1e-15) {
        if (a < -eps) empty = true;
      } else if (b > 0) {
        lo = std::max(lo, (-a - eps) / b);
      } else {
        hi = std::min(hi, (-a - eps) / b);
      }
    };
    limit(a0, w0x);
    limit(a1, w1x);
    limit(a2, b2);
    if (empty || lo > hi) continue;
    const int xs = std::max(x0, static_cast<int>(std::ceil(lo))), xe = std::min(x1, static_cast<int>(std::floor(hi)));
    float* drow = t.depth->ptr<float>(y);
    cv::Vec3b* crow = t.colour->ptr<cv::Vec3b>(y);
    uint16_t* lrow = t.label->ptr<uint16_t>(y);
    const float izr = static_cast<float>(a0 * iza + a1 * izb + a2 * izc), izxf = static_cast<float>(izx);
    for (int x = xs; x <= xe; ++x) {
      const float iz = izr + izxf * x;
      if (iz <= 0.0f) continue;
      const float z = 1.0f / iz;
      if (drow[x] != 0.0f && z >= drow[x]) continue;
      drow[x] = z;
      crow[x] = col;
      lrow[x] = lid;
    }
  }
}
}  // namespace

uint8_t Renderer::encodeSrgb(float linear) {
  static const std::vector<uint8_t> lut = [] {
    std::vector<uint8_t> l(4097);
    for (int i = 0; i <= 4096; ++i) {
      const double c = i / 4096.0;
      const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
      l[i] = static_cast<uint8_t>(std::lround(std::min(1.0, s) * 255));
    }
    return l;
  }();
  const int i = static_cast<int>(linear * 4096.0f + 0.5f);
  return lut[i < 0 ? 0 : (i > 4096 ? 4096 : i)];
}

float Renderer::decodeSrgb(uint8_t code) {
  static const std::vector<float> lut = [] {
    std::vector<float> l(256);
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      l[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return l;
  }();
  return lut[code];
}

void Renderer::render(const std::vector<RenderItem>& items, const CameraModel& cam,
                      const Eigen::Isometry3d& world_T_camera, RenderOutput& out,
                      const Eigen::Vector3f& gain) const {
  out.colour.create(cam.height, cam.width, CV_8UC3);
  out.colour.setTo(cv::Scalar::all(0));
  out.depth.create(cam.height, cam.width, CV_32FC1);
  out.depth.setTo(cv::Scalar::all(0));
  out.label.create(cam.height, cam.width, CV_16UC1);
  out.label.setTo(cv::Scalar::all(0));
  Target target{&out.colour, &out.depth, &out.label};
  const Eigen::Isometry3d camera_T_world = world_T_camera.inverse();
  const Eigen::Vector3d light = Eigen::Vector3d(0.25, 0.15, 1.0).normalized();
  for (const RenderItem& item : items) {
    if (!item.mesh) continue;
    const Mesh& m = *item.mesh;
    const Eigen::Isometry3d T = camera_T_world * item.pose;
    if (m.radius >= 0.0) {
      // whole item outside the view frustum?
      const Eigen::Vector3d c = T.translation();
      const double r = m.radius;
      if (c.z() < cam.near - r || c.z() > cam.far + r) continue;
      const double kx = cam.width / (2.0 * cam.fx) + std::abs(cam.cx - cam.width / 2.0) / cam.fx;
      const double ky = cam.height / (2.0 * cam.fy) + std::abs(cam.cy - cam.height / 2.0) / cam.fy;
      const double zc = std::max(c.z(), 0.0);
      if (std::abs(c.x()) - r * std::sqrt(1 + kx * kx) > kx * zc + r || std::abs(c.y()) - r * std::sqrt(1 + ky * ky) > ky * zc + r) {
        continue;
      }
    }
    cam_vertices_.resize(m.vertices.size());
    for (size_t i = 0; i < m.vertices.size(); ++i) cam_vertices_[i] = T * m.vertices[i];
    for (size_t k = 0; k < m.triangles.size(); ++k) {
      const auto& tri = m.triangles[k];
      const Eigen::Vector3d& a = cam_vertices_[tri[0]];
      const Eigen::Vector3d& b = cam_vertices_[tri[1]];
      const Eigen::Vector3d& c = cam_vertices_[tri[2]];
      if (a.z() > cam.far && b.z() > cam.far && c.z() > cam.far) continue;
      if (m.cull_back_faces && (b - a).cross(c - a).dot(a) >= 0.0) continue;
      const Eigen::Vector3d n_local = (m.vertices[tri[1]] - m.vertices[tri[0]]).cross(m.vertices[tri[2]] - m.vertices[tri[0]]);
      const double len = n_local.norm();
      if (len < 1e-15) continue;
      const Eigen::Vector3d n = item.pose.linear() * (n_local / len);
      const float shade = static_cast<float>(0.35 + 0.65 * std::abs(n.dot(light)));
      const Eigen::Vector3f lin = m.colours[k].cwiseProduct(gain) * shade;
      const cv::Vec3b colour(encodeSrgb(lin.x()), encodeSrgb(lin.y()), encodeSrgb(lin.z()));
      const Eigen::Vector3d* v[3] = {&a, &b, &c};
      int inside = 0;
      for (auto* p : v) inside += p->z() >= cam.near;
      if (inside == 3) {
        rasterTriangle(a, b, c, cam, colour, item.id, target);
        continue;
      }
      if (inside == 0) continue;
      // clip against the near plane (Sutherland-Hodgman), then fan
      Eigen::Vector3d poly[4];
      int n_out = 0;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d& p = *v[i];
        const Eigen::Vector3d& q = *v[(i + 1) % 3];
        const bool pin = p.z() >= cam.near, qin = q.z() >= cam.near;
        if (pin) poly[n_out++] = p;
        if (pin != qin) {
          const double s = (cam.near - p.z()) / (q.z() - p.z());
          poly[n_out++] = p + s * (q - p);
        }
      }
      for (int i = 1; i + 1 < n_out; ++i) rasterTriangle(poly[0], poly[i], poly[i + 1], cam, colour, item.id, target);
    }
  }
}

}  // namespace rascal_sim
