// ShellFit on synthetic shells seen as the wrist camera sees them: 0.5 mm depth pixels,
// the D435's depth noise at 0.30 m (σ 0.38 mm, ../shared/facts/widowx250_d435.md §4.4) and its
// 1 mm depth units.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "rascal_perception/ShellFit.hpp"

using namespace rascal_perception;

namespace {

struct Shell {
  double length = 0.060, width = 0.040, thickness = 0.008;
  double curvature = 0.0, curvature_long = 0.0;  ///< [1/m] across and along
  bool convex_up = true;
  double tilt = 0.0;  ///< [rad] about the long axis
};

constexpr double kCameraRange = 0.3004;  // [m] to the table (not a whole mm: quantisation shows)
constexpr double kDepthSigma = 0.00038;  // [m] at 0.30 m, 640x480 (facts §4.4)
constexpr double kPixel = 0.0005;        // [m] a depth pixel on the table at that range

/// Top-surface samples of `s` lying on the table (vertical wall thickness s.thickness).
std::vector<TopSample> seen(const Shell& s, unsigned seed, bool noisy = true) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kDepthSigma);
  const double a = s.length / 2, b = s.width / 2;
  const double sign = s.convex_up ? 1.0 : -1.0;
  auto mid = [&](double x, double y) {
    return -sign * (s.curvature * y * y + s.curvature_long * x * x) / 2 + std::tan(s.tilt) * y;
  };
  double lowest = 1e9;
  for (double x = -a; x <= a; x += kPixel / 4) {
    for (double y = -b; y <= b; y += kPixel / 4) {
      if ((x * x) / (a * a) + (y * y) / (b * b) <= 1.0) lowest = std::min(lowest, mid(x, y));
    }
  }
  std::vector<TopSample> out;
  for (double x = -a; x <= a; x += kPixel) {
    for (double y = -b; y <= b; y += kPixel) {
      const double r = std::sqrt((x * x) / (a * a) + (y * y) / (b * b));
      if (r > 1.0) continue;
      const double h = mid(x, y) - lowest + s.thickness;  // the bottom rests on the table
      double z = kCameraRange - h;
      if (noisy) z = std::round((z + noise(rng)) * 1000.0) / 1000.0;
      const double edge = (1.0 - r) * std::min(a, b);  // about the distance to the outline
      out.push_back({x, y, kCameraRange - z, edge > 3 * kPixel});
    }
  }
  return out;
}

double highest(const std::vector<TopSample>& v) {
  double h = 0.0;
  for (const TopSample& s : v) h = std::max(h, s.h);
  return h;
}

}  // namespace

TEST(ShellFit, AFlatSherdIsItsHeight) {
  Shell s;
  const ShellFit w = ShellFit::estimate(seen(s, 1));
  ASSERT_TRUE(w.valid) << w.why;
  EXPECT_NEAR(w.thickness, 0.008, 0.0003);
  EXPECT_LT(w.rms, 0.0006);
}

TEST(ShellFit, ACurvedSherdIsItsWallNotItsHeight) {
  // 15 /m across (a 67 mm radius: a small bowl), 4 /m along; on either face, tilted or not
  for (bool convex_up : {true, false}) {
    for (double tilt : {0.0, 0.08}) {
      for (unsigned seed = 1; seed <= 5; ++seed) {
        Shell s;
        s.curvature = 15.0;
        s.curvature_long = 4.0;
        s.convex_up = convex_up;
        s.tilt = tilt;
        s.thickness = 0.004 + 0.002 * seed;
        const std::vector<TopSample> v = seen(s, seed);
        const ShellFit w = ShellFit::estimate(v);
        ASSERT_TRUE(w.valid) << w.why;
        EXPECT_NEAR(w.thickness, s.thickness, 0.0006) << "convex_up " << convex_up << " tilt " << tilt;
        EXPECT_GT(highest(v) - s.thickness, 0.003);  // what the height as it lies would have said
      }
    }
  }
}

TEST(ShellFit, ATopThatIsNoShellGivesNoThickness) {
  // a rim or a foot ring: a 5 mm step across the sherd
  std::vector<TopSample> v = seen(Shell(), 3, false);
  for (TopSample& s : v) s.h += s.x > 0.0 ? 0.005 : 0.0;
  const ShellFit w = ShellFit::estimate(v);
  EXPECT_FALSE(w.valid);
  EXPECT_NE(w.why.find("no smooth shell"), std::string::npos) << w.why;
}

TEST(ShellFit, TooFewDepthPixelsGiveNoThickness) {
  Shell s;
  s.length = 0.006;
  s.width = 0.005;
  const ShellFit w = ShellFit::estimate(seen(s, 4));
  EXPECT_FALSE(w.valid);
  EXPECT_NE(w.why.find("too few depth pixels"), std::string::npos) << w.why;
}

TEST(ShellFit, FlyingPixelsAtTheOutlineDoNotPullItDown) {
  // the outline's pixels read the table's depth half of the time (mixed depth at the edge)
  std::vector<TopSample> v = seen(Shell(), 5);
  for (size_t i = 0; i < v.size(); i += 2) {
    if (!v[i].interior) v[i].h = 0.0005;
  }
  const ShellFit w = ShellFit::estimate(v);
  ASSERT_TRUE(w.valid) << w.why;
  EXPECT_NEAR(w.thickness, 0.008, 0.0003);
}

TEST(ShellFit, TheVesselDiameterFromTheStrongestCurvature) {
  // The top surface curves 1/R across: convex up it is the outer face (diameter 2R); concave up
  // it is the inner face of a wall `thickness` thick (outer diameter 2(R + thickness)).
  for (double curvature : {5.0, 10.0, 15.0}) {  // 400, 200, 133 mm (body of a jar, a jug, a bowl)
    for (bool convex_up : {true, false}) {
      for (double tilt : {0.0, 0.08}) {
        Shell s;
        s.curvature = curvature;
        s.curvature_long = 1.0;
        s.convex_up = convex_up;
        s.tilt = tilt;
        const ShellFit w = ShellFit::estimate(seen(s, static_cast<unsigned>(curvature * 10) + convex_up));
        ASSERT_TRUE(w.valid) << w.why;
        const double truth = 2.0 / curvature + (convex_up ? 0.0 : 2.0 * s.thickness);
        ASSERT_GT(w.diameter, 0.0) << w.diameter_why;
        EXPECT_EQ(w.concave_up, !convex_up);
        EXPECT_NEAR(w.diameter, truth, 0.15 * truth) << "curvature " << curvature << " convex_up " << convex_up;
        EXPECT_GT(w.diameter_sigma, 0.0);
        EXPECT_LT(std::fabs(w.diameter - truth), 3.0 * w.diameter_sigma + 0.03 * truth) << "sigma too small";
      }
    }
  }
}

TEST(ShellFit, AFlatOrSmallSherdHasNoDiameter) {
  Shell flat;  // a tile, or a sherd of a very big vessel
  ShellFit w = ShellFit::estimate(seen(flat, 7));
  ASSERT_TRUE(w.valid) << w.why;
  EXPECT_EQ(w.diameter, 0.0);
  EXPECT_NE(w.diameter_why.find("too flat or too small"), std::string::npos) << w.diameter_why;
  Shell small;  // 14 x 10 mm of a 400 mm jar: its sagitta (0.1 mm) is below the depth's noise
  small.length = 0.014;
  small.width = 0.010;
  small.curvature = 5.0;
  w = ShellFit::estimate(seen(small, 8));
  EXPECT_EQ(w.diameter, 0.0) << w.diameter * 1e3 << " ± " << w.diameter_sigma * 1e3 << " mm";
}
