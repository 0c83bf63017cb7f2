#include "rascal_perception/WallThickness.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rascal_perception {

namespace {
constexpr int kTerms = 6;  // 1, x, y, x², xy, y²

Eigen::Matrix<double, 1, kTerms> terms(double x, double y) {
  Eigen::Matrix<double, 1, kTerms> t;
  t << 1.0, x, y, x * x, x * y, y * y;
  return t;
}
}  // namespace

WallThickness WallThickness::estimate(const std::vector<TopSample>& samples) {
  WallThickness out;
  // centred and in mm: the quadric's terms then have comparable sizes
  double cx = 0.0, cy = 0.0, top = 0.0;
  int n = 0;
  for (const TopSample& s : samples) {
    top = std::max(top, s.h);
    if (!s.interior) continue;
    cx += s.x;
    cy += s.y;
    ++n;
  }
  out.samples = n;
  if (n < kMinSamples) {
    out.why = "too few depth pixels inside its outline (" + std::to_string(n) + ")";
    return out;
  }
  cx /= n;
  cy /= n;
  std::vector<bool> use(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) use[i] = samples[i].interior;
  Eigen::Matrix<double, kTerms, 1> coef = Eigen::Matrix<double, kTerms, 1>::Zero();
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::Matrix<double, kTerms, kTerms> ata = Eigen::Matrix<double, kTerms, kTerms>::Zero();
    Eigen::Matrix<double, kTerms, 1> atb = Eigen::Matrix<double, kTerms, 1>::Zero();
    int used = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!use[i]) continue;
      const auto t = terms((samples[i].x - cx) * 1e3, (samples[i].y - cy) * 1e3);
      ata.noalias() += t.transpose() * t;
      atb.noalias() += t.transpose() * (samples[i].h * 1e3);
      ++used;
    }
    if (used < kMinSamples) {
      out.why = "too few depth pixels agree on one surface";
      return out;
    }
    coef = ata.ldlt().solve(atb);
    double ss = 0.0;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!use[i]) continue;
      const double r = terms((samples[i].x - cx) * 1e3, (samples[i].y - cy) * 1e3) * coef - samples[i].h * 1e3;
      ss += r * r;
    }
    out.rms = std::sqrt(ss / used) * 1e-3;
    out.samples = used;
    if (pass == 0) {  // flying pixels, a chip of glaze: not the shell
      const double limit = std::max(3.0 * out.rms, 0.0005) * 1e3;
      for (size_t i = 0; i < samples.size(); ++i) {
        if (!samples[i].interior) continue;
        const double r = terms((samples[i].x - cx) * 1e3, (samples[i].y - cy) * 1e3) * coef - samples[i].h * 1e3;
        use[i] = std::fabs(r) <= limit;
      }
    }
  }
  if (!std::isfinite(out.rms) || out.rms > kMaxRms) {
    char text[120];
    std::snprintf(text, sizeof(text), "its top is no smooth shell (%.1f mm from the fitted surface)", out.rms * 1e3);
    out.why = text;
    return out;
  }
  double lowest = 1e9;
  for (const TopSample& s : samples) {
    lowest = std::min(lowest, (terms((s.x - cx) * 1e3, (s.y - cy) * 1e3) * coef).value() * 1e-3);
  }
  out.thickness = std::clamp(lowest, 0.0, top);
  out.valid = out.thickness > 0.0;
  if (!out.valid) out.why = "the fitted top surface reaches the table";
  return out;
}

}  // namespace rascal_perception
