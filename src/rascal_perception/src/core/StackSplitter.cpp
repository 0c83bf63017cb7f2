#include "rascal_perception/StackSplitter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>

#include "rascal_perception/SherdSegmenter.hpp"

namespace rascal_perception {

namespace {
constexpr int kPad = 6;        ///< [px] looked at around the blob (its neighbours' edges)
constexpr int kReach = 2;      ///< [px] a step is measured between pixels 2 * kReach apart
constexpr int kBand = 3;       ///< [px] either side of a shared edge, compared for which part is higher
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

float median(std::vector<float>& v) {
  if (v.empty()) return kNaN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
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
  std::vector<int> keep;  // component labels big enough to be a sherd
  for (int i = 1; i < n; ++i) {
    if (stats.at<int>(i, cv::CC_STAT_AREA) >= options.min_area_px) keep.push_back(i);
  }
  if (keep.size() < 2) return whole;
  // every other pixel of the blob goes to the part it is nearest to (grown 1 px at a time)
  cv::Mat part(roi.size(), CV_32S, cv::Scalar(-1));
  for (size_t k = 0; k < keep.size(); ++k) part.setTo(static_cast<int>(k), labels == keep[k]);
  for (bool grew = true; grew;) {
    grew = false;
    cv::Mat next = part.clone();
    for (int y = 0; y < mask.rows; ++y) {
      for (int x = 0; x < mask.cols; ++x) {
        if (!mask.at<uint8_t>(y, x) || part.at<int>(y, x) >= 0) continue;
        for (const cv::Point& d : {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
          const cv::Point q(x + d.x, y + d.y);
          if (q.x < 0 || q.y < 0 || q.x >= mask.cols || q.y >= mask.rows || part.at<int>(q) < 0) continue;
          next.at<int>(y, x) = part.at<int>(q);
          grew = true;
          break;
        }
      }
    }
    part = next;
  }
  std::vector<cv::Mat> masks(keep.size());
  std::vector<int> edge_px(keep.size(), 0), under_px(keep.size(), 0);
  for (size_t k = 0; k < keep.size(); ++k) masks[k] = part == static_cast<int>(k);
  std::vector<StackPart> out(keep.size());
  const cv::Mat band = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kBand + 1, 2 * kBand + 1));
  const cv::Mat ring = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  std::vector<cv::Mat> near(keep.size());
  for (size_t k = 0; k < keep.size(); ++k) cv::dilate(masks[k], near[k], band);
  for (size_t i = 0; i < keep.size(); ++i) {
    cv::Mat grown, outline;
    cv::dilate(masks[i], grown, ring);
    outline = grown & ~masks[i];  // the pixels just outside part i
    edge_px[i] = cv::countNonZero(outline);
    for (size_t j = 0; j < keep.size(); ++j) {
      if (i == j) continue;
      const cv::Mat shared = outline & masks[j];
      const int len = cv::countNonZero(shared);
      if (len == 0) continue;
      // which side of the shared edge is higher: i's pixels near j against j's pixels near i
      std::vector<float> hi, hj;
      const cv::Mat bi = masks[i] & near[j], bj = masks[j] & near[i];
      for (int y = 0; y < mask.rows; ++y) {
        for (int x = 0; x < mask.cols; ++x) {
          const float v = h.at<float>(y, x);
          if (v != v) continue;
          if (bi.at<uint8_t>(y, x)) hi.push_back(v);
          if (bj.at<uint8_t>(y, x)) hj.push_back(v);
        }
      }
      const float mi = median(hi), mj = median(hj);
      if (!(mi == mi && mj == mj)) continue;
      if (mj > mi + step / 2) {
        under_px[i] += len;  // j lies on i along this edge
      } else if (mi > mj + step / 2) {
        out[i].support = std::max(out[i].support, static_cast<double>(mj));  // i lies on j
      }
    }
  }
  for (size_t k = 0; k < keep.size(); ++k) {
    cv::Rect box = cv::boundingRect(masks[k]);
    out[k].blob = SherdSegmenter::blobOf(masks[k](box), box.tl() + roi.tl());
    out[k].covered = edge_px[k] > 0 ? static_cast<double>(under_px[k]) / edge_px[k] : 0.0;
  }
  return out;
}

}  // namespace rascal_perception
