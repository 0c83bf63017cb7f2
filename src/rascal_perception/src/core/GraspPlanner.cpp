#include "rascal_perception/GraspPlanner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rascal_perception {

namespace {
/// Distance from point p to segment ab in the xy plane.
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// Across-extent [lo, hi] (along `across`, about `centre`) of the outline's part within `half_band`
/// of `shift` along `along`: what two fingers that wide, centred there, close on. False when the
/// band misses the outline.
bool bandExtent(const std::vector<Eigen::Vector3d>& outline, const Eigen::Vector2d& centre,
                const Eigen::Vector2d& along, const Eigen::Vector2d& across, double shift, double half_band,
                double& lo, double& hi) {
  lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const double a0 = shift - half_band, a1 = shift + half_band;
  for (size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d p = outline[i].head<2>() - centre, q = outline[(i + 1) % outline.size()].head<2>() - centre;
    double pa = along.dot(p), qa = along.dot(q), pt = across.dot(p), qt = across.dot(q);
    if ((pa < a0 && qa < a0) || (pa > a1 && qa > a1)) continue;
    // the edge clipped to the band
    for (const double a : {a0, a1}) {
      if ((pa - a) * (qa - a) < 0.0) {
        const double t = pt + (qt - pt) * (a - pa) / (qa - pa);
        lo = std::min(lo, t), hi = std::max(hi, t);
      }
    }
    if (pa >= a0 && pa <= a1) lo = std::min(lo, pt), hi = std::max(hi, pt);
    if (qa >= a0 && qa <= a1) lo = std::min(lo, qt), hi = std::max(hi, qt);
  }
  return hi > lo;
}

/// The height map's value where base_link point `p` projects, into `under`: none off the image,
/// on the sherd's own mask (seen there, its top hides what lies past its edge; between the
/// fingers it is what they close on), or without depth.
void heightUnder(const GraspContext& ctx, const Eigen::Isometry3d& camera_T_base, const Eigen::Vector3d& p,
                 std::vector<float>& under) {
  const Eigen::Vector3d q = camera_T_base * p;
  if (q.z() <= 0.0) return;
  const cv::Mat& height = *ctx.height;
  const Eigen::Vector2d uv = ctx.view->intrinsics.project(q);
  const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
  if (x < 0 || y < 0 || x >= height.cols || y >= height.rows) return;
  if (ctx.own && ctx.own->bounds.contains(cv::Point(x, y)) &&
      ctx.own->mask.at<uint8_t>(y - ctx.own->bounds.y, x - ctx.own->bounds.x)) {
    return;
  }
  const float h = height.at<float>(y, x);
  if (h == h) under.push_back(h);
}

/// The `blocking`-th highest of `under` (reordered): a neighbour's corner under that many
/// samples blocks what comes down there, fewer (a flying pixel or two at an edge) do not.
double blockingHeight(std::vector<float>& under, size_t blocking) {
  const size_t k = under.size() > blocking ? under.size() - blocking : 0;
  std::nth_element(under.begin(), under.begin() + k, under.end());
  return under[k];
}

double outlineGap(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& p : a) {
    for (size_t i = 0; i < b.size(); ++i) {
      best = std::min(best, segmentDistance(p.head<2>(), b[i].head<2>(), b[(i + 1) % b.size()].head<2>()));
    }
  }
  return best;
}
}  // namespace

double GraspPlanner::holdCost(const Offer& offer, double elongation) {
  const double turn = std::sin(offer.turn_deg * M_PI / 180.0);
  return offer.shift * offer.shift + turn * turn * std::clamp(elongation / kElongated, 0.0, 1.0);
}

GraspPlanner::GraspPlanner(const PerceptionConfig& config) : config_(config) {
  const rascal_workcell::GripperGeometry& g = config_.gripper;
  if (!(g.minOpening() > 0.0 && g.maxOpening() > g.minOpening())) {
    throw std::invalid_argument(
        "GraspPlanner: PerceptionConfig::gripper has no finger limits; fill it from the URDF "
        "(rascal_workcell::GripperGeometry::fromUrdf or fromPackageUrdf)");
  }
}

void GraspPlanner::plan(SherdDetection& s, const GraspContext* context) const {
  // from what the sherd rests on (the station, or the sherd under it in a heap: closing lower
  // would take that one too)
  const double own = std::max(s.height - s.support, 0.0);
  double tip = s.support + std::max(config_.grasp_height_fraction * own, config_.grasp_tip_clearance);
  double yaw = s.yaw;
  Eigen::Vector2d centre = s.centre.head<2>();
  double opening = std::clamp(s.width + config_.grasp_margin, minOpening(), maxOpening());
  if (context && context->height && context->view && !context->height->empty() && s.outline.size() >= 3) {
    struct Candidate {
      double yaw, opening, clear, chord;
      Eigen::Vector2d centre;
      double tip;
    };
    std::vector<Candidate> candidates;
    double chord0 = 0.0;  // across the minor axis
    const double elongation = s.length > 0.0 ? 1.0 - s.width / s.length : 0.0;
    std::vector<Offer> offers(std::begin(kOffers), std::end(kOffers));
    std::stable_sort(offers.begin(), offers.end(), [elongation](const Offer& a, const Offer& b) {
      return holdCost(a, elongation) < holdCost(b, elongation);
    });
    for (const Offer& offer : offers) {
      const double y = s.yaw + offer.turn_deg * M_PI / 180.0;
      const Eigen::Vector2d across(-std::sin(y), std::cos(y));  // the fingers close along R*y
      const Eigen::Vector2d along(std::cos(y), std::sin(y));
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      const double shift = offer.shift * s.length / 2;
      if (shift == 0.0) {
        for (const Eigen::Vector3d& p : s.outline) {
          const double t = across.dot(p.head<2>() - s.centre.head<2>());
          lo = std::min(lo, t);
          hi = std::max(hi, t);
        }
      } else if (!bandExtent(s.outline, s.centre.head<2>(), along, across, shift, kFingerWidth / 2, lo, hi)) {
        continue;
      }
      if (offer.turn_deg == 0.0 && shift == 0.0) chord0 = hi - lo;
      const double need = hi - lo + config_.grasp_margin;
      if (need > maxOpening()) continue;
      const double open = std::clamp(need, minOpening(), maxOpening());
      const Eigen::Vector2d c = s.centre.head<2>() + along * shift + across * (lo + hi) / 2;
      const double at = tipAtChordEnds(y, hi - lo, c, s.surface, tip, own, *context);
      candidates.push_back({y, open, fingerClearance(y, open, c, s.surface, at, *context), hi - lo, c, at});
    }
    // the first clear one the fingers can hold, the hand above them clear too; else the
    // clearest they can hold; else the clearest
    const Candidate* pick = nullptr;
    for (Candidate& c : candidates) {
      if (c.clear >= kFingerClearance && c.chord >= holdableChord()) {
        c.clear = std::min(c.clear, handClearance(c.yaw, c.centre, s.surface, c.tip, *context));
        if (c.clear < kFingerClearance) continue;
        pick = &c;
        break;
      }
    }
    const bool clear = pick != nullptr;
    for (int holdable = 1; holdable >= 0 && !pick; --holdable) {
      for (const Candidate& c : candidates) {
        if ((!holdable || c.chord >= holdableChord()) && (!pick || c.clear > pick->clear)) pick = &c;
      }
    }
    if (pick) yaw = pick->yaw, centre = pick->centre, opening = pick->opening, tip = pick->tip;
    s.finger_clearance = pick ? pick->clear : -1.0;
    // a long chord is still the grasp to try (nothing nearer the minor axis is clear), but not
    // offered as clear: the task layer takes other sherds first. A sherd too narrow to hold
    // across its minor axis has to be turned.
    s.grasp_clear = clear && (pick->chord <= kMaxChordRatio * chord0 || chord0 < holdableChord());
  }
  yaw = wrapHalfPi(yaw);  // the two fingers are alike: yaw and yaw + pi are one grasp
  s.grasp = Eigen::Isometry3d::Identity();
  s.grasp.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY())).toRotationMatrix();
  s.grasp.translation() = Eigen::Vector3d(centre.x(), centre.y(), s.surface + tip + config_.gripper.fingertip_offset);
  s.grasp_width = opening;
}

double GraspPlanner::tipAtChordEnds(double yaw, double chord, const Eigen::Vector2d& centre, double surface,
                                    double tip, double own, const GraspContext& ctx) const {
  if (!ctx.own) return tip;
  const cv::Mat& height = *ctx.height;
  const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw)), along(std::cos(yaw), std::sin(yaw));
  const Eigen::Isometry3d camera_T_base = ctx.view->base_T_camera.inverse();
  const Blob& b = *ctx.own;
  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (const double side : {-1.0, 1.0}) {
    std::vector<float> top;  // the sherd's own heights where this finger meets it
    for (double t = 0.0; t <= kEndBand + 1e-9; t += 0.002) {
      for (double u = -kFingerWidth / 2; u <= kFingerWidth / 2 + 1e-9; u += 0.002) {
        const Eigen::Vector2d p = centre + across * side * (chord / 2 - t) + along * u;
        const Eigen::Vector3d q = camera_T_base * Eigen::Vector3d(p.x(), p.y(), surface + tip);
        if (q.z() <= 0.0) continue;
        const Eigen::Vector2d uv = ctx.view->intrinsics.project(q);
        const int x = static_cast<int>(std::lround(uv.x())), y = static_cast<int>(std::lround(uv.y()));
        if (!b.bounds.contains(cv::Point(x, y)) || !b.mask.at<uint8_t>(y - b.bounds.y, x - b.bounds.x)) continue;
        if (x >= height.cols || y >= height.rows) continue;
        const float h = height.at<float>(y, x);
        if (h == h) top.push_back(h);
      }
    }
    if (top.empty()) return tip;  // an end not seen: nothing to go by
    const size_t k = top.size() * 3 / 4;  // the edge's pixels mixed with the ground read low
    std::nth_element(top.begin(), top.begin() + k, top.end());
    lowest = std::min(lowest, static_cast<double>(top[k]));
    highest = std::max(highest, static_cast<double>(top[k]));
  }
  if (highest - lowest > kSteepRise * chord) return tip;  // standing steeply: not held low
  // as far under the lower end's top as the rule closes under a flat sherd's top
  const double bite = (1.0 - config_.grasp_height_fraction) * own;
  return std::max(std::min(tip, lowest - bite), config_.grasp_tip_clearance);
}

double GraspPlanner::fingerClearance(double yaw, double opening, const Eigen::Vector2d& centre, double surface,
                                     double tip, const GraspContext& ctx) const {
  const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw)), along(std::cos(yaw), std::sin(yaw));
  const Eigen::Isometry3d camera_T_base = ctx.view->base_T_camera.inverse();
  double worst = std::numeric_limits<double>::infinity();
  for (const double side : {-1.0, 1.0}) {
    std::vector<float> under;  // heights the finger's footprint looks down on
    // the finger with its pad, from the opening outwards
    for (double t = 0.0; t <= kFingerThickness + config_.gripper.pad + 1e-9; t += 0.002) {
      for (double u = -kFingerWidth / 2; u <= kFingerWidth / 2 + 1e-9; u += 0.002) {
        const Eigen::Vector2d p = centre + across * side * (opening / 2 + t) + along * u;
        heightUnder(ctx, camera_T_base, Eigen::Vector3d(p.x(), p.y(), surface + tip), under);
      }
    }
    if (!under.empty()) worst = std::min(worst, tip - blockingHeight(under, kBlockingSamples));
  }
  return worst;
}

double GraspPlanner::handClearance(double yaw, const Eigen::Vector2d& centre, double surface, double tip,
                                   const GraspContext& ctx) const {
  // pointing down at yaw: ee x is down, y across (the closing direction), z along
  const Eigen::Vector2d across(-std::sin(yaw), std::cos(yaw)), along(std::cos(yaw), std::sin(yaw));
  const Eigen::Isometry3d camera_T_base = ctx.view->base_T_camera.inverse();
  const double ee = surface + tip + config_.gripper.fingertip_offset;  // ee_gripper_link's z
  double worst = std::numeric_limits<double>::infinity();
  for (const rascal_workcell::HandBox& b : config_.gripper.hand) {
    const double bottom = ee - b.hi[0];
    for (const double turn : {1.0, -1.0}) {  // the grasp, and the grasp turned by pi
      std::vector<float> under;
      for (double v = b.lo[1]; v <= b.hi[1] + 1e-9; v += kHandStep) {
        for (double w = b.lo[2]; w <= b.hi[2] + 1e-9; w += kHandStep) {
          const Eigen::Vector2d p = centre + turn * (across * v + along * w);
          heightUnder(ctx, camera_T_base, Eigen::Vector3d(p.x(), p.y(), bottom), under);
        }
      }
      if (!under.empty()) worst = std::min(worst, bottom - surface - blockingHeight(under, kBlockingSamples));
    }
  }
  return worst;
}

void GraspPlanner::score(std::vector<SherdDetection>& sherds) const {
  for (size_t i = 0; i < sherds.size(); ++i) {
    double gap = 1.0;
    for (size_t j = 0; j < sherds.size(); ++j) {
      if (i == j || sherds[i].outline.empty() || sherds[j].outline.empty()) continue;
      gap = std::min({gap, outlineGap(sherds[i].outline, sherds[j].outline),
                      outlineGap(sherds[j].outline, sherds[i].outline)});
    }
    SherdDetection& s = sherds[i];
    s.clearance = gap;
    const double isolation = std::clamp(gap / kFingerWidth, 0.0, 1.0);
    const double fit = s.width + config_.grasp_margin <= maxOpening() ? 1.0 : 0.3;
    const double depth = s.depth_valid ? 1.0 : 0.5;
    s.score = fit * depth * (0.5 + 0.5 * isolation) * (s.grasp_clear ? 1.0 : 0.5);
  }
}

}  // namespace rascal_perception
