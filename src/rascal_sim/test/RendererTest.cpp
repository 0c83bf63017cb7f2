#include <gtest/gtest.h>

#include <cmath>

#include "rascal_sim/Renderer.hpp"
#include "rascal_sim/SensorEffects.hpp"
#include "rascal_sim/SherdMeshBuilder.hpp"

using namespace rascal_sim;

namespace {
/// Optical frame `height` above (x, y), looking straight down (image x = world x).
Eigen::Isometry3d downward(double x, double y, double height) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  T.linear() = r;
  T.translation() = Eigen::Vector3d(x, y, height);
  return T;
}

Eigen::Vector2d polygonCentroid(const std::vector<Eigen::Vector2d>& p) {
  double a = 0;
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d& u = p[i];
    const Eigen::Vector2d& v = p[(i + 1) % p.size()];
    const double cr = u.x() * v.y() - v.x() * u.y();
    a += cr;
    c += (u + v) * cr;
  }
  return c / (3 * a);
}
}  // namespace

TEST(Renderer, SherdCentroidLandsOnItsPinholeProjection) {
  SherdSpec s;
  s.name = "flat";
  s.outline = {{-0.03, -0.015}, {0.01, -0.022}, {0.031, 0.004}, {0.012, 0.021}, {-0.024, 0.018}};
  s.thickness = 0.008;
  const SherdGeometry g = SherdMeshBuilder::build(s);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.21, 0.03, g.box_size.z() / 2);
  const CameraModel cam = CameraModel::wristD435();
  const Eigen::Isometry3d camera = downward(0.2, 0.0, 0.30);
  Renderer renderer;
  RenderOutput out;
  renderer.render({{&g.mesh, pose, 7}}, cam, camera, out);
  double su = 0, sv = 0, n = 0;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      if (out.label.at<uint16_t>(v, u) == 7) {
        su += u;
        sv += v;
        n += 1;
      }
    }
  }
  ASSERT_GT(n, 1000);
  // the top face is flat and parallel to the image: its area centroid projects onto the mask's
  const Eigen::Vector2d c = polygonCentroid(g.outline);
  const Eigen::Vector3d top = pose * Eigen::Vector3d(c.x(), c.y(), g.box_size.z() / 2);
  const Eigen::Vector2d uv = cam.project(camera.inverse() * top);
  EXPECT_NEAR(su / n, uv.x(), 1.0);
  EXPECT_NEAR(sv / n, uv.y(), 1.0);
}

TEST(Renderer, DepthIsWithinTheNoiseModelOfTheTrueDistance) {
  Mesh table;
  table.addRect(0.3, 0.0, 2.0, 2.0, 0.0, {0.5, 0.5, 0.5});
  const CameraModel cam = CameraModel::wristD435();
  const double h = 0.40;
  Renderer renderer;
  RenderOutput out;
  renderer.render({{&table, Eigen::Isometry3d::Identity(), 1}}, cam, downward(0.3, 0.0, h), out);
  SensorEffects effects(5);
  const cv::Mat depth = effects.depthImage(out.depth, cam);
  const double sigma = SensorEffects::depthSigma(h);  // facts §4.4: Z^2 sigma_d / (f B)
  double sum = 0, sum2 = 0, n = 0, worst = 0;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const uint16_t mm = depth.at<uint16_t>(v, u);
      ASSERT_GT(mm, 0);
      const double e = mm / 1000.0 - h;
      sum += e;
      sum2 += e * e;
      n += 1;
      worst = std::max(worst, std::abs(e));
    }
  }
  const double mean = sum / n, rms = std::sqrt(sum2 / n);
  EXPECT_NEAR(mean, 0.0, 0.0002);
  // quantised to 1 mm: rms between the bare noise and noise plus quantisation
  EXPECT_LE(rms, std::sqrt(sigma * sigma + 0.001 * 0.001 / 12) * 1.1);
  EXPECT_GE(rms, sigma * 0.9);
  EXPECT_LE(worst, 6 * sigma + 0.0005);
}

TEST(Renderer, NearerSurfaceHidesFartherOne) {
  Mesh m;
  m.addRect(0.0, 0.0, 0.2, 0.2, 0.0, {0.2, 0.2, 0.2});
  Mesh box;
  box.addBox({0.0, 0.0, 0.05}, {0.04, 0.04, 0.1}, {0.9, 0.1, 0.1});
  const CameraModel cam = CameraModel::wristD435();
  Renderer renderer;
  RenderOutput out;
  renderer.render({{&box, Eigen::Isometry3d::Identity(), 2}, {&m, Eigen::Isometry3d::Identity(), 1}}, cam,
                  downward(0, 0, 0.5), out);
  EXPECT_EQ(out.label.at<uint16_t>(240, 320), 2);
  EXPECT_NEAR(out.depth.at<float>(240, 320), 0.4, 1e-5);
  EXPECT_EQ(out.label.at<uint16_t>(240, 260), 1);
}

TEST(SensorEffects, ArchivalCameraVignettesTonesAndCompressesLikeACamera) {
  rascal_sim::CameraModel cam;
  cam.width = 600;
  cam.height = 400;
  cam.fx = cam.fy = 500.0;
  cam.cx = 300.0;
  cam.cy = 200.0;
  cv::Mat flat(cam.height, cam.width, CV_8UC3, cv::Scalar(150, 150, 150));
  cv::Mat img = flat.clone();
  rascal_sim::SensorEffects::archivalCamera(img, cam);
  ASSERT_EQ(img.size(), flat.size());
  ASSERT_EQ(img.type(), CV_8UC3);
  // the lens: a corner gets cos^4 of its field angle of the centre's light
  const double t2 = (300.0 * 300.0 + 200.0 * 200.0) / (500.0 * 500.0);
  const double expected = 1.0 / ((1.0 + t2) * (1.0 + t2));
  const auto tone = [](double linear) {  // the picture style's S on the sRGB code
    const double v = rascal_sim::Renderer::encodeSrgb(static_cast<float>(linear)) / 255.0;
    return 255.0 * (v - rascal_sim::SensorEffects::kToneContrast * std::sin(2.0 * M_PI * v) / (2.0 * M_PI));
  };
  const double light = rascal_sim::Renderer::decodeSrgb(150);
  EXPECT_NEAR(img.at<cv::Vec3b>(200, 300)[1], tone(light), 2.0);
  EXPECT_NEAR(img.at<cv::Vec3b>(2, 2)[1], tone(light * expected), 3.0);
  // the tone curve: a mid-grey stays (the S crosses at 0.5), darker greys get darker
  cv::Mat greys(64, 64, CV_8UC3);
  for (int x = 0; x < 64; ++x) greys.col(x).setTo(cv::Scalar::all(x < 32 ? 64 : 128));
  cam.width = cam.height = 64;
  cam.cx = cam.cy = 32.0;
  cam.fx = cam.fy = 1e6;  // no vignetting
  rascal_sim::SensorEffects::archivalCamera(greys, cam);
  EXPECT_LT(greys.at<cv::Vec3b>(32, 8)[0], 60);
  EXPECT_NEAR(greys.at<cv::Vec3b>(32, 56)[0], 128, 2);
}
