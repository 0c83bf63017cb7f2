#include "rascal_control/AnalyticIk.hpp"

#include <cmath>

namespace rascal_control {

namespace {

constexpr double kAxisTolerance = 1e-9;
constexpr double kPointTolerance = 1e-9;
constexpr double kSingular = 1e-9;

double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

bool sameAxis(const KDL::Vector& a, const KDL::Vector& b) {
  return (a - b).Norm() < kAxisTolerance;
}

// Rotation about +y by `angle` of a vector (r, z) in the arm plane.
void rotatePlane(double angle, double r, double z, double& r_out, double& z_out) {
  r_out = r * std::cos(angle) + z * std::sin(angle);
  z_out = -r * std::sin(angle) + z * std::cos(angle);
}

}  // namespace

bool AnalyticIk::extract(const KDL::Chain& chain, Geometry& geometry, std::string& why) {
  std::vector<KDL::Vector> points;
  std::vector<KDL::Vector> axes;
  KDL::Frame pose = KDL::Frame::Identity();
  for (const KDL::Segment& segment : chain.segments) {
    const KDL::Joint& joint = segment.getJoint();
    if (joint.getType() != KDL::Joint::None) {
      points.push_back(pose * joint.JointOrigin());
      axes.push_back(pose.M * joint.JointAxis());
    }
    pose = pose * segment.pose(0.0);
  }
  if (points.size() != kArmJoints) {
    why = "the chain has " + std::to_string(points.size()) + " moving joints, not 6";
    return false;
  }
  const KDL::Vector x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const KDL::Vector expected[kArmJoints] = {z, y, y, x, y, x};
  for (std::size_t i = 0; i < kArmJoints; ++i) {
    if (!sameAxis(axes[i], expected[i])) {
      why = "joint " + std::to_string(i) + " axis is not the wx250s axis";
      return false;
    }
    if (std::fabs(points[i].y()) > kPointTolerance) {
      why = "joint " + std::to_string(i) + " is out of the arm plane y = 0";
      return false;
    }
  }
  if (std::fabs(points[0].x()) > kPointTolerance) {
    why = "the waist axis is not the base_link z axis";
    return false;
  }
  // Wrist centre: wrist_angle's point moved onto the x axes of forearm_roll and wrist_rotate.
  const KDL::Vector wrist(points[4].x(), 0.0, points[4].z());
  if (std::fabs(points[3].z() - wrist.z()) > kPointTolerance ||
      std::fabs(points[5].z() - wrist.z()) > kPointTolerance) {
    why = "the wrist axes do not meet in one point";
    return false;
  }
  if (std::fabs(pose.p.y()) > kPointTolerance) {
    why = "the tip is out of the arm plane";
    return false;
  }
  geometry.shoulder = KDL::Vector(points[1].x(), 0.0, points[1].z());
  geometry.elbow = KDL::Vector(points[2].x(), 0.0, points[2].z());
  geometry.wrist = wrist;
  geometry.tip_home = pose;
  return true;
}

AnalyticIk::AnalyticIk(const Geometry& geometry) : geometry_(geometry) {
  tip_offset_ = geometry_.tip_home.M.Inverse() * (geometry_.tip_home.p - geometry_.wrist);
  l1r_ = geometry_.elbow.x() - geometry_.shoulder.x();
  l1z_ = geometry_.elbow.z() - geometry_.shoulder.z();
  l2r_ = geometry_.wrist.x() - geometry_.elbow.x();
  l2z_ = geometry_.wrist.z() - geometry_.elbow.z();
}

double AnalyticIk::maxReach() const {
  return std::hypot(l1r_, l1z_) + std::hypot(l2r_, l2z_);
}

double AnalyticIk::minReach() const {
  return std::fabs(std::hypot(l1r_, l1z_) - std::hypot(l2r_, l2z_));
}

bool AnalyticIk::solveAll(const KDL::Frame& target, const JointVector& seed,
                          std::vector<JointVector>& out, double& reach_error) const {
  out.clear();
  reach_error = 0.0;
  // Wrist centre in base_link; the tip frame is R_target * R_home^-1 applied to the home frame.
  const KDL::Rotation r06 = target.M * geometry_.tip_home.M.Inverse();
  const KDL::Vector w = target.p - target.M * tip_offset_;
  const double rho = std::hypot(w.x(), w.y());
  const double waist_front = rho < kSingular ? seed[0] : std::atan2(w.y(), w.x());

  // Elbow: |L1 + R(q3) L2| = |D| gives A cos(q3) + B sin(q3) = C.
  const double a = l1r_ * l2r_ + l1z_ * l2z_;
  const double b = l1r_ * l2z_ - l1z_ * l2r_;
  const double l1sq = l1r_ * l1r_ + l1z_ * l1z_;
  const double l2sq = l2r_ * l2r_ + l2z_ * l2z_;
  const double phi = std::atan2(b, a);
  const double ab = std::hypot(a, b);

  double best_reach_error = 1e9;
  for (int front = 0; front < 2; ++front) {
    const double q1 = wrapAngle(front == 0 ? waist_front : waist_front + M_PI);
    const double r = front == 0 ? rho : -rho;
    const double dr = r - geometry_.shoulder.x();
    const double dz = w.z() - geometry_.shoulder.z();
    const double c = (dr * dr + dz * dz - l1sq - l2sq) / 2.0;
    const double ratio = c / ab;
    if (std::fabs(ratio) > 1.0) {
      const double d = std::hypot(dr, dz);
      best_reach_error = std::min(best_reach_error, std::max(d - maxReach(), minReach() - d));
      continue;
    }
    const double spread = std::acos(std::min(1.0, std::max(-1.0, ratio)));
    for (int up = 0; up < 2; ++up) {
      if (up == 1 && spread < kSingular) {
        continue;  // both elbow solutions coincide
      }
      const double q3 = wrapAngle(up == 0 ? phi + spread : phi - spread);
      double vr = 0.0, vz = 0.0;
      rotatePlane(q3, l2r_, l2z_, vr, vz);
      vr += l1r_;
      vz += l1z_;
      // R(q2) V = D; R(q2) turns a plane vector by -q2.
      const double q2 = wrapAngle(std::atan2(vz, vr) - std::atan2(dz, dr));
      // Wrist: Rx(q4) Ry(q5) Rx(q6) = Ry(q2+q3)^T Rz(q1)^T R06.
      const KDL::Rotation r36 = KDL::Rotation::RotY(-(q2 + q3)) * KDL::Rotation::RotZ(-q1) * r06;
      const double c5 = std::min(1.0, std::max(-1.0, r36(0, 0)));
      const double s5abs = std::hypot(r36(0, 1), r36(0, 2));
      if (s5abs < 1e-10) {
        // Wrist singular: only q4 + q6 (or q4 - q6) is defined; keep q4 at the seed.
        const double q4 = seed[3];
        const double q5 = c5 > 0.0 ? 0.0 : M_PI;
        const double sum = std::atan2(r36(2, 1), r36(1, 1));
        const double q6 = c5 > 0.0 ? sum - q4 : q4 - sum;
        out.push_back({q1, q2, q3, wrapAngle(q4), wrapAngle(q5), wrapAngle(q6)});
        continue;
      }
      for (int flip = 0; flip < 2; ++flip) {
        const double s5 = flip == 0 ? s5abs : -s5abs;
        const double q5 = std::atan2(s5, c5);
        const double q4 = std::atan2(r36(1, 0) / s5, -r36(2, 0) / s5);
        const double q6 = std::atan2(r36(0, 1) / s5, r36(0, 2) / s5);
        out.push_back({q1, q2, q3, q4, q5, q6});
      }
    }
  }
  if (out.empty()) {
    reach_error = best_reach_error;
    return false;
  }
  return true;
}

}  // namespace rascal_control
