#include "rascal_perception/SherdSegmenter.hpp"

#include <algorithm>
#include <numeric>
#include <queue>
#include <opencv2/imgproc.hpp>

namespace rascal_perception {

std::vector<Blob> SherdSegmenter::segment(const cv::Mat& rgb, const BackgroundModel& model, const cv::Mat& allowed,
                                          const cv::Mat& fixture, const cv::Mat& raised,
                                          const SegmentationOptions& options, cv::Mat& foreground,
                                          SegmentationStats* stats) const {
  model.classifyRgb(rgb, allowed, background_);
  cv::bitwise_not(background_, foreground);
  if (!raised.empty()) cv::bitwise_or(foreground, raised, foreground);
  if (!fixture.empty()) foreground.setTo(0, fixture);
  cv::morphologyEx(foreground, foreground, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  cv::morphologyEx(foreground, foreground, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
  return blobs(foreground, options, stats);
}

namespace {
// A blob filling this much of its convex hull has no neck to split at (two touching sherds
// leave a notch on each side: about 0.8-0.9).
constexpr double kConvex = 0.95;

Blob blobOfContour(const std::vector<cv::Point>& contour) {
  Blob b;
  b.contour = contour;
  b.bounds = cv::boundingRect(b.contour);
  b.mask = cv::Mat::zeros(b.bounds.size(), CV_8U);
  cv::drawContours(b.mask, std::vector<std::vector<cv::Point>>{b.contour}, 0, cv::Scalar(255), cv::FILLED,
                   cv::LINE_8, cv::noArray(), 0, -b.bounds.tl());
  b.pixels = cv::countNonZero(b.mask);
  b.box = cv::minAreaRect(b.contour);
  return b;
}
}  // namespace

Blob SherdSegmenter::blobOf(const cv::Mat& part, const cv::Point& offset) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(part, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, offset);
  if (contours.empty()) return Blob();
  size_t best = 0;
  for (size_t i = 1; i < contours.size(); ++i) {
    if (cv::contourArea(contours[i]) > cv::contourArea(contours[best])) best = i;
  }
  return blobOfContour(contours[best]);
}

std::vector<Blob> SherdSegmenter::blobs(const cv::Mat& mask, const SegmentationOptions& options,
                                        SegmentationStats* stats) const {
  SegmentationStats local;
  SegmentationStats& st = stats ? *stats : local;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::vector<Blob> out;
  const double noise_area = 0.5 * options.min_side_px * options.min_side_px;
  const int m = options.border_margin;
  for (const auto& c : contours) {
    if (cv::contourArea(c) < noise_area) continue;
    const cv::Rect r = cv::boundingRect(c);
    if (options.check && (r.x < m || r.y < m || r.x + r.width > mask.cols - m || r.y + r.height > mask.rows - m)) {
      ++st.rejected_border;
      continue;
    }
    // Most blobs are one convex sherd: no neck to split at, and the contour is the blob's own
    // (the camera-rate path spends most of its time below otherwise).
    std::vector<Blob> found;
    std::vector<cv::Point> hull;
    cv::convexHull(c, hull);
    if (!options.split || cv::contourArea(c) >= kConvex * cv::contourArea(hull)) {
      found.push_back(blobOfContour(c));
    } else {
      // a 1 px frame so the distance transform sees the blob's edge everywhere
      const cv::Rect padded(r.x - 1, r.y - 1, r.width + 2, r.height + 2);
      cv::Mat filled = cv::Mat::zeros(padded.size(), CV_8U);
      cv::drawContours(filled, std::vector<std::vector<cv::Point>>{c}, 0, cv::Scalar(255), cv::FILLED, cv::LINE_8,
                       cv::noArray(), 0, -padded.tl());
      const std::vector<cv::Mat> parts = split(filled, options.split_min_neck, 0.25 * options.min_side_px);
      if (parts.size() > 1) st.splits += static_cast<int>(parts.size()) - 1;
      for (const cv::Mat& p : parts) found.push_back(blobOf(p, padded.tl()));
    }
    for (Blob& b : found) {
      if (b.contour.empty()) continue;
      if (options.check && !accept(b, mask.size(), options, st)) continue;
      out.push_back(std::move(b));
    }
  }
  return out;
}

BlobCheck SherdSegmenter::check(const Blob& b, const cv::Size& image, const SegmentationOptions& options) {
  const int m = options.border_margin;
  const cv::Rect& r = b.bounds;
  if (r.x < m || r.y < m || r.x + r.width > image.width - m || r.y + r.height > image.height - m) {
    return BlobCheck::kCutByBorder;
  }
  if (std::min(b.box.size.width, b.box.size.height) < options.min_side_px) return BlobCheck::kTooSmall;
  if (std::max(b.box.size.width, b.box.size.height) > options.max_side_px) return BlobCheck::kTooLarge;
  return BlobCheck::kAccepted;
}

bool SherdSegmenter::accept(const Blob& b, const cv::Size& image, const SegmentationOptions& options,
                            SegmentationStats& st) {
  switch (check(b, image, options)) {
    case BlobCheck::kAccepted:
      return true;
    case BlobCheck::kCutByBorder:
      ++st.rejected_border;
      return false;
    default:
      ++st.rejected_size;
      return false;
  }
}

std::vector<cv::Mat> SherdSegmenter::split(const cv::Mat& mask, double min_neck, double min_peak_px) const {
  cv::Mat dist;
  cv::distanceTransform(mask, dist, cv::DIST_L2, cv::DIST_MASK_5);
  double maxd = 0.0;
  cv::minMaxLoc(dist, nullptr, &maxd);
  if (maxd < min_peak_px || maxd < 2.0) return {mask};
  // peaks: local maxima of the distance, at least 35 % of the deepest
  const int r = std::max(2, static_cast<int>(0.3 * maxd));
  cv::Mat dilated;
  cv::dilate(dist, dilated, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1)));
  const double floor = std::max(min_peak_px, 0.35 * maxd);
  cv::Mat peak_mask = (dist >= dilated) & (dist >= floor);
  cv::Mat peak_labels, peak_stats, centroids;
  const int n = cv::connectedComponentsWithStats(peak_mask, peak_labels, peak_stats, centroids, 8, CV_32S) - 1;
  if (n <= 1) return {mask};
  struct Peak { cv::Point p; float v; };
  std::vector<Peak> peaks;
  for (int i = 1; i <= n; ++i) {
    cv::Point p(peak_stats.at<int>(i, cv::CC_STAT_LEFT), peak_stats.at<int>(i, cv::CC_STAT_TOP));
    // a pixel of the component (its top-left may lie outside it)
    for (int y = p.y; y < p.y + peak_stats.at<int>(i, cv::CC_STAT_HEIGHT); ++y) {
      bool found = false;
      for (int x = p.x; x < p.x + peak_stats.at<int>(i, cv::CC_STAT_WIDTH); ++x) {
        if (peak_labels.at<int>(y, x) == i) {
          p = {x, y};
          found = true;
          break;
        }
      }
      if (found) break;
    }
    peaks.push_back({p, dist.at<float>(p)});
  }
  // two peaks are one sherd if a path joins them without dropping below min_neck x the smaller
  std::vector<int> group(peaks.size());
  std::iota(group.begin(), group.end(), 0);
  auto root = [&](int i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  // For a pair the threshold is set by the lower peak, so one labelling per peak at its own
  // threshold decides all its pairs with higher peaks (one pass per peak, not per pair: a
  // blob of many sherds has dozens of peaks).
  cv::Mat labels;
  for (size_t i = 0; i < peaks.size(); ++i) {
    cv::connectedComponents(dist >= static_cast<float>(min_neck) * peaks[i].v, labels, 8, CV_32S);
    const int li = labels.at<int>(peaks[i].p);
    for (size_t j = 0; j < peaks.size(); ++j) {
      if (j == i || peaks[j].v < peaks[i].v || (peaks[j].v == peaks[i].v && j < i)) continue;
      if (labels.at<int>(peaks[j].p) == li) group[root(static_cast<int>(j))] = root(static_cast<int>(i));
    }
  }
  std::vector<int> roots;
  for (size_t i = 0; i < peaks.size(); ++i) {
    const int g = root(static_cast<int>(i));
    if (std::find(roots.begin(), roots.end(), g) == roots.end()) roots.push_back(g);
  }
  if (roots.size() <= 1) return {mask};
  // watershed by flooding the inverted distance (Meyer): deepest pixels first, one marker per group
  cv::Mat markers = cv::Mat::zeros(mask.size(), CV_32S);
  using Item = std::pair<float, cv::Point>;
  auto lower = [](const Item& a, const Item& b) { return a.first < b.first; };
  std::priority_queue<Item, std::vector<Item>, decltype(lower)> queue(lower);
  for (size_t i = 0; i < peaks.size(); ++i) {
    const int g = static_cast<int>(std::find(roots.begin(), roots.end(), root(static_cast<int>(i))) - roots.begin());
    markers.at<int>(peaks[i].p) = g + 1;
    queue.push({peaks[i].v, peaks[i].p});
  }
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  while (!queue.empty()) {
    const cv::Point p = queue.top().second;
    queue.pop();
    const int label = markers.at<int>(p);
    for (const cv::Point& s : steps) {
      const cv::Point q = p + s;
      if (q.x < 0 || q.y < 0 || q.x >= mask.cols || q.y >= mask.rows) continue;
      if (!mask.at<uint8_t>(q) || markers.at<int>(q) != 0) continue;
      markers.at<int>(q) = label;
      queue.push({dist.at<float>(q), q});
    }
  }
  std::vector<cv::Mat> parts;
  for (size_t g = 0; g < roots.size(); ++g) {
    cv::Mat part = (markers == static_cast<int>(g) + 1) & mask;
    if (cv::countNonZero(part) > 0) parts.push_back(part);
  }
  return parts.empty() ? std::vector<cv::Mat>{mask} : parts;
}

}  // namespace rascal_perception
