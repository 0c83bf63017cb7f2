#include "rascal_perception/ShellFit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rascal_perception {

namespace {
constexpr int kTerms = 6;  // 1, x, y, x², xy, y² (x, y in mm from the samples' centre)
using Terms = Eigen::Matrix<double, 1, kTerms>;
using Coefficients = Eigen::Matrix<double, kTerms, 1>;

Terms terms(double x, double y) {
  Terms t;
  t << 1.0, x, y, x * x, x * y, y * y;
  return t;
}

/// The strongest curvature of the fitted surface [1/mm] (signed: > 0 concave up), its 1-sigma
/// uncertainty from the fit's covariance (rms² (AᵀA)⁻¹, [mm²] on the coefficients) and the
/// curvature across it (`other`, signed).
void strongestCurvature(const Coefficients& c, const Eigen::Matrix<double, kTerms, kTerms>& cov, double& kappa,
                        double& sigma, double& other, Eigen::Vector2d& direction) {
  Eigen::Matrix2d hessian;
  hessian << 2.0 * c(3), c(4), c(4), 2.0 * c(5);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(hessian);
  const int k = std::fabs(eig.eigenvalues()(0)) >= std::fabs(eig.eigenvalues()(1)) ? 0 : 1;
  const Eigen::Vector2d v = eig.eigenvectors().col(k);
  direction = v;
  // a tilted sherd: the graph's curvature along v at the centre, h'' / (1 + h'²)^1.5
  const double slope = c(1) * v.x() + c(2) * v.y();
  const double stretch = std::pow(1.0 + slope * slope, 1.5);
  kappa = eig.eigenvalues()(k) / stretch;
  other = eig.eigenvalues()(1 - k);
  // d(lambda) = vᵀ dH v over the coefficients (d, e, f) = (x², xy, y²)
  Eigen::Vector3d j(2.0 * v.x() * v.x(), 2.0 * v.x() * v.y(), 2.0 * v.y() * v.y());
  sigma = std::sqrt(std::max(0.0, j.dot(cov.block<3, 3>(3, 3) * j))) / stretch;
}
}  // namespace

ShellFit ShellFit::estimate(const std::vector<TopSample>& samples) {
  ShellFit out;
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
    out.why = out.diameter_why = "too few depth pixels inside its outline (" + std::to_string(n) + ")";
    return out;
  }
  cx /= n;
  cy /= n;
  auto at = [&](const TopSample& s) { return terms((s.x - cx) * 1e3, (s.y - cy) * 1e3); };
  std::vector<bool> use(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) use[i] = samples[i].interior;
  Coefficients coef = Coefficients::Zero();
  Eigen::Matrix<double, kTerms, kTerms> ata;
  for (int pass = 0; pass < 2; ++pass) {
    ata.setZero();
    Coefficients atb = Coefficients::Zero();
    int used = 0;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!use[i]) continue;
      const Terms t = at(samples[i]);
      ata.noalias() += t.transpose() * t;
      atb.noalias() += t.transpose() * (samples[i].h * 1e3);
      ++used;
    }
    if (used < kMinSamples) {
      out.why = out.diameter_why = "too few depth pixels agree on one surface";
      return out;
    }
    coef = ata.ldlt().solve(atb);
    double ss = 0.0;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (!use[i]) continue;
      const double r = at(samples[i]) * coef - samples[i].h * 1e3;
      ss += r * r;
    }
    out.rms = std::sqrt(ss / used) * 1e-3;
    out.samples = used;
    if (pass == 0) {  // flying pixels, a chip of glaze: not the shell
      const double limit = std::max(3.0 * out.rms, 0.0005) * 1e3;
      for (size_t i = 0; i < samples.size(); ++i) {
        if (samples[i].interior) use[i] = std::fabs(at(samples[i]) * coef - samples[i].h * 1e3) <= limit;
      }
    }
  }
  if (!std::isfinite(out.rms) || out.rms > kMaxRms) {
    char text[120];
    std::snprintf(text, sizeof(text), "its top is no smooth shell (%.1f mm from the fitted surface)", out.rms * 1e3);
    out.why = out.diameter_why = text;
    return out;
  }
  double lowest = 1e9;
  for (const TopSample& s : samples) lowest = std::min(lowest, (at(s) * coef).value() * 1e-3);
  out.thickness = std::clamp(lowest, 0.0, top);
  out.valid = out.thickness > 0.0;
  if (!out.valid) {
    out.why = out.diameter_why = "the fitted top surface reaches the table";
    return out;
  }

  // The vessel: the strongest curvature of the top surface is the vessel's around its axis.
  double kappa = 0.0, sigma = 0.0, other = 0.0;  // [1/mm]
  Eigen::Vector2d along;
  const Eigen::Matrix<double, kTerms, kTerms> cov = (out.rms * 1e3) * (out.rms * 1e3) * ata.inverse();
  strongestCurvature(coef, cov, kappa, sigma, other, along);
  // the depth the curve spans over the sherd's extent that way: chord e, sagitta e^2 kappa / 8
  double lo = 1e9, hi = -1e9;
  for (const TopSample& s : samples) {
    const double u = along.x() * s.x + along.y() * s.y;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  const double chord = std::max(0.0, hi - lo);  // [m]
  const double sagitta = chord * chord * std::fabs(kappa) * 1e3 / 8.0;  // [m]
  out.concave_up = kappa > 0.0;
  const double radius = 1e-3 / std::max(std::fabs(kappa), 1e-9);  // [m] of the face that is up
  // the outer face is the top when convex; concave, the top is the inner face, a wall inside it
  out.diameter = 2.0 * (radius + (out.concave_up ? out.thickness : 0.0));
  out.diameter_sigma = 2.0 * radius * (sigma / std::max(std::fabs(kappa), 1e-12));
  if (std::fabs(other) > kMaxCrossCurvature * std::fabs(kappa) &&
      out.diameter_sigma <= kMaxRelativeSigma * out.diameter && out.diameter <= kMaxDiameter) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "curved both ways alike (radii %.0f and %.0f mm: a shoulder, a neck?): which way is the "
                  "vessel's circumference is not told",
                  1.0 / std::fabs(kappa), 1.0 / std::max(std::fabs(other), 1e-9));
    out.diameter_why = text;
    out.diameter = out.diameter_sigma = 0.0;
  } else if (out.diameter > kMaxDiameter || out.diameter_sigma > kMaxRelativeSigma * out.diameter ||
             sagitta < kMinSagitta) {
    char text[200];
    std::snprintf(text, sizeof(text), "too flat or too small to tell (%.0f ± %.0f mm; curve %.1f mm deep over %.0f mm)",
                  out.diameter * 1e3, out.diameter_sigma * 1e3, sagitta * 1e3, chord * 1e3);
    out.diameter_why = text;
    out.diameter = out.diameter_sigma = 0.0;
  }
  return out;
}

}  // namespace rascal_perception
