#include "rascal_perception/StackSplitter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <opencv2/imgproc.hpp>

#include "rascal_perception/SherdSegmenter.hpp"

namespace rascal_perception {

namespace {
constexpr int kPad = 6;        ///< [px] looked at around the blob (its neighbours' edges)
constexpr int kReach = 2;      ///< [px] a step is measured between pixels 2 * kReach apart
constexpr int kBand = 3;       ///< [px] either side of a shared edge, compared for which part is higher
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
/// a piece the steps cut off is an island (a neighbour's edge, or noise) if at least this
/// fraction (1/k) of the least part's area; smaller ones are ignored
constexpr int kIslandShare = 8;
/// a neighbour of another blob higher along a shared edge lies on the part there if its
/// underside is at least this fraction of the part's top height up (the rest: a concave-up
/// neighbour's rim, raised by its curvature, and the depth camera's millimetre)
constexpr float kRestsOn = 0.5f;

float median(std::vector<float>& v) {
  if (v.empty()) return kNaN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

/// The heights either side of the edge between the pieces `a` and `b` (masks over `h`;
/// `near_a`/`near_b`: each dilated by kBand): medians of a's pixels near b and of b's near a.
struct EdgeHeights {
  float a = kNaN, b = kNaN;  ///< [m]
  /// +1 when b is higher by half a step, -1 when a is, 0 when neither (or either has no height)
  int higher(float step) const {
    if (!(a == a && b == b)) return 0;
    return b > a + step / 2 ? 1 : a > b + step / 2 ? -1 : 0;
  }
};

EdgeHeights edgeHeights(const cv::Mat& h, const cv::Mat& a, const cv::Mat& b, const cv::Mat& near_a,
                        const cv::Mat& near_b) {
  std::vector<float> ha, hb;
  const cv::Mat ba = a & near_b, bb = b & near_a;
  for (int y = 0; y < h.rows; ++y) {
    for (int x = 0; x < h.cols; ++x) {
      const float v = h.at<float>(y, x);
      if (v != v) continue;
      if (ba.at<uint8_t>(y, x)) ha.push_back(v);
      if (bb.at<uint8_t>(y, x)) hb.push_back(v);
    }
  }
  return {median(ha), median(hb)};
}

const cv::Mat& bandKernel() {
  static const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kBand + 1, 2 * kBand + 1));
  return k;
}

const cv::Mat& ringKernel() {
  static const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  return k;
}

/// The pixels just outside `mask` (its 8-neighbours not in it), within `mask`'s own size.
cv::Mat outlineOf(const cv::Mat& mask) {
  cv::Mat grown;
  cv::dilate(mask, grown, ringKernel());
  return grown & ~mask;
}
}  // namespace

cv::Mat StackSplitter::heightMap(const cv::Mat& depth_mm, const CameraView& view, const Eigen::Vector4d& plane,
                                 double depth_min, double depth_max) {
  cv::Mat h(depth_mm.size(), CV_32F, cv::Scalar(kNaN));
  if (depth_mm.empty()) return h;
  const CameraIntrinsics& k = view.intrinsics;
  // h = n.(R ray z + t) + w = z (n.R ray) + (n.t + w)
  const Eigen::Vector3d nr = view.base_T_camera.linear().transpose() * plane.head<3>();
  const double offset = plane.head<3>().dot(view.base_T_camera.translation()) + plane.w();
  const uint16_t lo = static_cast<uint16_t>(depth_min * 1000.0);
  const uint16_t hi = static_cast<uint16_t>(std::min(65535.0, depth_max * 1000.0));
  for (int y = 0; y < depth_mm.rows; ++y) {
    const uint16_t* d = depth_mm.ptr<uint16_t>(y);
    float* o = h.ptr<float>(y);
    const double ry = (y - k.cy) / k.fy;
    for (int x = 0; x < depth_mm.cols; ++x) {
      if (d[x] < lo || d[x] > hi) continue;
      const double dot = nr.x() * (x - k.cx) / k.fx + nr.y() * ry + nr.z();
      o[x] = static_cast<float>(d[x] * 0.001 * dot + offset);
    }
  }
  return h;
}

std::vector<StackPart> StackSplitter::split(const Blob& blob, const cv::Mat& height,
                                            const StackOptions& options) const {
  std::vector<StackPart> whole(1);
  whole[0].blob = blob;
  if (height.empty() || blob.mask.empty()) return whole;
  // the blob's box and a margin, clipped to the image; the blob's mask placed in it
  const cv::Rect roi = (blob.bounds + cv::Size(2 * kPad, 2 * kPad) - cv::Point(kPad, kPad)) &
                       cv::Rect(0, 0, height.cols, height.rows);
  cv::Mat mask = cv::Mat::zeros(roi.size(), CV_8U);
  blob.mask.copyTo(mask(cv::Rect(blob.bounds.tl() - roi.tl(), blob.bounds.size())));
  cv::Mat h = height(roi).clone();
  {
    // the D435's pixel noise (~0.4 mm at 0.3 m) must not make steps: a 3 x 3 median where valid
    cv::Mat filled = h.clone(), smooth;
    filled.setTo(0.0f, h != h);
    cv::medianBlur(filled, smooth, 3);
    smooth.copyTo(h, h == h);
  }
  const float step = static_cast<float>(options.step);
  cv::Mat edge = cv::Mat::zeros(roi.size(), CV_8U);
  const cv::Point dirs[4] = {{kReach, 0}, {0, kReach}, {kReach, kReach}, {kReach, -kReach}};
  for (int y = 0; y < mask.rows; ++y) {
    for (int x = 0; x < mask.cols; ++x) {
      if (!mask.at<uint8_t>(y, x)) continue;
      for (const cv::Point& d : dirs) {
        const cv::Point a(x - d.x, y - d.y), b(x + d.x, y + d.y);
        if (a.x < 0 || a.y < 0 || b.x < 0 || b.y < 0 || a.x >= mask.cols || b.x >= mask.cols || a.y >= mask.rows ||
            b.y >= mask.rows) {
          continue;
        }
        if (!mask.at<uint8_t>(a) || !mask.at<uint8_t>(b)) continue;  // the blob's own outline
        const float ha = h.at<float>(a), hb = h.at<float>(b);
        if (ha == ha && hb == hb && std::fabs(ha - hb) > step) {
          edge.at<uint8_t>(y, x) = 255;
          break;
        }
      }
    }
  }
  if (cv::countNonZero(edge) == 0) return whole;
  cv::Mat cores = mask.clone();
  cores.setTo(0, edge);
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(cores, labels, stats, centroids, 4, CV_32S);
  // components big enough to be a sherd (parts), and islands: pieces the steps cut off that are
  // too small to be one. An island higher than the part around it is the edge of a neighbour
  // lying on it, the rest of that neighbour cut apart by the segmenter's neck split (a sherd's
  // end over another's: heap_25_offcentre seed 70, a finger came down on the neighbour)
  std::vector<int> keep, islands;
  const int min_island = std::max(1, options.min_area_px / kIslandShare);
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area >= options.min_area_px) {
      keep.push_back(i);
    } else if (area >= min_island) {
      islands.push_back(i);
    }
  }
  if (keep.empty() || (keep.size() == 1 && islands.empty())) return whole;
  // every other pixel of the blob goes to the piece (part or island) it is nearest to (grown 1 px
  // at a time)
  const size_t pieces = keep.size() + islands.size();
  cv::Mat piece(roi.size(), CV_32S, cv::Scalar(-1));
  for (size_t k = 0; k < keep.size(); ++k) piece.setTo(static_cast<int>(k), labels == keep[k]);
  for (size_t k = 0; k < islands.size(); ++k) piece.setTo(static_cast<int>(keep.size() + k), labels == islands[k]);
  for (bool grew = true; grew;) {
    grew = false;
    cv::Mat next = piece.clone();
    for (int y = 0; y < mask.rows; ++y) {
      for (int x = 0; x < mask.cols; ++x) {
        if (!mask.at<uint8_t>(y, x) || piece.at<int>(y, x) >= 0) continue;
        for (const cv::Point& d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
          const cv::Point q(x + d.x, y + d.y);
          if (q.x < 0 || q.y < 0 || q.x >= mask.cols || q.y >= mask.rows || piece.at<int>(q) < 0) continue;
          next.at<int>(y, x) = piece.at<int>(q);
          grew = true;
          break;
        }
      }
    }
    piece = next;
  }
  std::vector<cv::Mat> masks(pieces);
  for (size_t k = 0; k < pieces; ++k) masks[k] = piece == static_cast<int>(k);
  std::vector<cv::Mat> near(pieces), outline(pieces);
  for (size_t k = 0; k < pieces; ++k) {
    cv::dilate(masks[k], near[k], bandKernel());
    outline[k] = outlineOf(masks[k]);
  }
  std::vector<int> edge_px(keep.size(), 0), under_px(keep.size(), 0);
  std::vector<StackPart> out(keep.size());
  for (size_t i = 0; i < keep.size(); ++i) {
    edge_px[i] = cv::countNonZero(outline[i]);
    for (size_t j = 0; j < pieces; ++j) {
      if (i == j) continue;
      const int len = cv::countNonZero(outline[i] & masks[j]);
      if (len == 0) continue;
      const EdgeHeights e = edgeHeights(h, masks[i], masks[j], near[i], near[j]);
      const int side = e.higher(step);
      if (side > 0) {
        under_px[i] += len;  // j lies on i along this edge
      } else if (side < 0 && j < keep.size()) {
        // i lies on part j (an island lower than i is not what it rests on: the mat's edge
        // mixed into a thick sherd's outline reads low too)
        out[i].support = std::max(out[i].support, static_cast<double>(e.b));
      }
    }
  }
  for (size_t k = 0; k < keep.size(); ++k) {
    out[k].covered = edge_px[k] > 0 ? static_cast<double>(under_px[k]) / edge_px[k] : 0.0;
  }
  if (keep.size() == 1) {
    whole[0].covered = out[0].covered;  // one sherd with a neighbour's edge on it: its outline as it was
    return whole;
  }
  // an island belongs to the part it shares the longest edge with (to the first part if it
  // touches only islands)
  std::vector<int> home(pieces, 0);
  for (size_t k = 0; k < keep.size(); ++k) home[k] = static_cast<int>(k);
  for (size_t m = keep.size(); m < pieces; ++m) {
    int longest = 0;
    for (size_t k = 0; k < keep.size(); ++k) {
      const int len = cv::countNonZero(outline[m] & masks[k]);
      if (len > longest) longest = len, home[m] = static_cast<int>(k);
    }
  }
  for (size_t k = 0; k < keep.size(); ++k) {
    cv::Mat own = masks[k].clone();
    for (size_t m = keep.size(); m < pieces; ++m) {
      if (home[m] == static_cast<int>(k)) own |= masks[m];
    }
    cv::Rect box = cv::boundingRect(own);
    out[k].blob = SherdSegmenter::blobOf(own(box), box.tl() + roi.tl());
  }
  return out;
}

std::vector<double> StackSplitter::coveredAcross(const std::vector<const Blob*>& parts, const std::vector<int>& group,
                                                 const std::vector<double>& walls, const cv::Mat& height,
                                                 const StackOptions& options) {
  std::vector<double> covered(parts.size(), 0.0);
  if (height.empty()) return covered;
  const cv::Rect image(0, 0, height.cols, height.rows);
  const cv::Size pad(2 * (kBand + 1), 2 * (kBand + 1));
  const cv::Point shift(kBand + 1, kBand + 1);
  for (size_t i = 0; i < parts.size(); ++i) {
    const cv::Rect around_i = (parts[i]->bounds + pad - shift) & image;
    int edge_px = -1, under_px = 0;  // i's outline (counted once, when it has a neighbour)
    for (size_t j = 0; j < parts.size(); ++j) {
      if (i == j || group[i] == group[j] || (around_i & parts[j]->bounds).empty()) continue;
      // both masks in one window around the two (and a band beyond)
      const cv::Rect roi = ((parts[i]->bounds | parts[j]->bounds) + pad - shift) & image;
      cv::Mat mi = cv::Mat::zeros(roi.size(), CV_8U), mj = cv::Mat::zeros(roi.size(), CV_8U);
      parts[i]->mask.copyTo(mi(cv::Rect(parts[i]->bounds.tl() - roi.tl(), parts[i]->bounds.size())));
      parts[j]->mask.copyTo(mj(cv::Rect(parts[j]->bounds.tl() - roi.tl(), parts[j]->bounds.size())));
      const int len = cv::countNonZero(outlineOf(mi) & mj);
      if (len == 0) continue;
      cv::Mat near_i, near_j;
      cv::dilate(mi, near_i, bandKernel());
      cv::dilate(mj, near_j, bandKernel());
      const cv::Mat h = height(roi);
      const EdgeHeights e = edgeHeights(h, mi, mj, near_i, near_j);
      // j lies on i there when its underside (its top less its wall) is up near i's top; a
      // thicker sherd merely beside i has its underside on the table
      if (e.higher(static_cast<float>(options.step)) > 0 && walls[j] > 0.0 && e.b - walls[j] >= kRestsOn * e.a) {
        under_px += len;
      }
      if (edge_px < 0) {
        // the outline of i alone: its mask padded by a pixel so the ring is not cut by its box
        cv::Mat padded = cv::Mat::zeros(parts[i]->mask.rows + 2, parts[i]->mask.cols + 2, CV_8U);
        parts[i]->mask.copyTo(padded(cv::Rect(1, 1, parts[i]->mask.cols, parts[i]->mask.rows)));
        edge_px = cv::countNonZero(outlineOf(padded));
      }
    }
    if (edge_px > 0) covered[i] = static_cast<double>(under_px) / edge_px;
  }
  return covered;
}

}  // namespace rascal_perception
