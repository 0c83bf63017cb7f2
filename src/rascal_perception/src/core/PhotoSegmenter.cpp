#include "rascal_perception/PhotoSegmenter.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace rascal_perception {

namespace {
constexpr double kTwoPi = 6.283185307179586;

cv::Vec3f feature(const cv::Vec3b& hsv) {
  const float h = hsv[0] / 256.0f, s = hsv[1] / 255.0f, v = hsv[2] / 255.0f;
  return {s * static_cast<float>(std::cos(kTwoPi * h)), s * static_cast<float>(std::sin(kTwoPi * h)), v};
}
}  // namespace

cv::Mat PhotoSegmenter::foreground(const cv::Mat& rgb, const cv::Mat& background) const {
  const cv::Mat& source = background.empty() ? rgb : background;
  cv::Mat hsv, hsv_src;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV_FULL);
  cv::cvtColor(source, hsv_src, cv::COLOR_RGB2HSV_FULL);
  const int step = std::max(1, static_cast<int>(std::sqrt(hsv_src.total() / 30000.0)));
  std::vector<cv::Vec3f> samples;
  for (int y = step / 2; y < hsv_src.rows; y += step) {
    for (int x = step / 2; x < hsv_src.cols; x += step) samples.push_back(feature(hsv_src.at<cv::Vec3b>(y, x)));
  }
  const int k = background.empty() ? options_.clusters : 1;
  cv::Mat labels, centres;
  const uint64_t saved_rng = cv::theRNG().state;  // seeded k-means, without touching others' RNG
  cv::theRNG().state = options_.seed;
  cv::kmeans(cv::Mat(static_cast<int>(samples.size()), 3, CV_32F, samples.data()), k, labels,
             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4), 3, cv::KMEANS_PP_CENTERS,
             centres);
  cv::theRNG().state = saved_rng;
  std::vector<int> count(k, 0);
  for (int i = 0; i < labels.rows; ++i) ++count[labels.at<int>(i)];
  const int largest = static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  auto nearest = [&](const cv::Vec3f& f, float* dist = nullptr) {
    int best = 0;
    float best_d = 1e9f;
    for (int c = 0; c < k; ++c) {
      const float* m = centres.ptr<float>(c);
      const float d = (f[0] - m[0]) * (f[0] - m[0]) + (f[1] - m[1]) * (f[1] - m[1]) + (f[2] - m[2]) * (f[2] - m[2]);
      if (d < best_d) {
        best_d = d;
        best = c;
      }
    }
    if (dist) *dist = best_d;
    return best;
  };
  // background: the largest cluster and every cluster that holds a tenth of the image's rim
  // (sherds and the bar lie inside the photo; the cloth's shades all reach its edges)
  std::vector<int> rim(k, 0);
  int rim_total = 0;
  const int band = std::max(2, std::min(hsv_src.rows, hsv_src.cols) / 50);
  for (int y = 0; y < hsv_src.rows; y += 2) {
    for (int x = 0; x < hsv_src.cols; x += 2) {
      if (y >= band && y < hsv_src.rows - band && x >= band && x < hsv_src.cols - band) continue;
      ++rim[nearest(feature(hsv_src.at<cv::Vec3b>(y, x)))];
      ++rim_total;
    }
  }
  std::vector<bool> is_bg(k, false);
  for (int c = 0; c < k; ++c) {
    is_bg[c] = c == largest || rim[c] >= 0.1 * rim_total ||
               cv::norm(centres.row(c) - centres.row(largest)) < options_.background_distance;
  }
  cv::Mat fg(rgb.size(), CV_8U);
  for (int y = 0; y < hsv.rows; ++y) {
    const cv::Vec3b* p = hsv.ptr<cv::Vec3b>(y);
    uint8_t* o = fg.ptr<uint8_t>(y);
    for (int x = 0; x < hsv.cols; ++x) {
      float best_d = 0.0f;
      const int best = nearest(feature(p[x]), &best_d);
      if (background.empty()) {
        o[x] = is_bg[best] ? 0 : 255;
      } else {
        o[x] = best_d > options_.background_distance * options_.background_distance ? 255 : 0;
      }
    }
  }
  cv::morphologyEx(fg, fg, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));

  // dark glaze and painted lines must not cut a sherd in pieces
  const int close = std::max(3, (rgb.cols / 200) | 1);
  cv::morphologyEx(fg, fg, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(close, close)));
  return fg;
}

ScaleBar PhotoSegmenter::findBar(const cv::Mat& rgb, std::vector<Blob>& blobs) const {
  ScaleBar bar;
  double best = 0.0;
  int index = -1;
  cv::Mat hsv;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV_FULL);
  for (size_t i = 0; i < blobs.size(); ++i) {
    const Blob& b = blobs[i];
    const double lo = std::min(b.box.size.width, b.box.size.height);
    const double hi = std::max(b.box.size.width, b.box.size.height);
    if (lo <= 0) continue;
    const double aspect = hi / lo;
    if (aspect < options_.bar_aspect_min || aspect > options_.bar_aspect_max) continue;
    const double fill = b.pixels / (lo * hi);
    if (fill < 0.85) continue;
    const double saturation = cv::mean(hsv(b.bounds), b.mask)[1] / 255.0;
    if (saturation > 0.35) continue;
    if (fill > best) {
      best = fill;
      index = static_cast<int>(i);
    }
  }
  if (index < 0) return bar;
  bar.found = true;
  bar.box = blobs[index].box;
  const double lo = std::min(bar.box.size.width, bar.box.size.height);
  const double hi = std::max(bar.box.size.width, bar.box.size.height);
  // A bar with a chequered half: its black parts may vanish into a dark cloth, leaving the white
  // row of the solid half (bar_length / 2 x 1 cm) and the white squares of the chequer beside it,
  // along its axis and as wide as it is tall. Then the rectangle is half the bar.
  const cv::Point2f axis = bar.box.size.width >= bar.box.size.height
                               ? cv::Point2f(std::cos(bar.box.angle * 0.0174533f), std::sin(bar.box.angle * 0.0174533f))
                               : cv::Point2f(-std::sin(bar.box.angle * 0.0174533f), std::cos(bar.box.angle * 0.0174533f));
  std::vector<size_t> squares;
  for (size_t i = 0; i < blobs.size(); ++i) {
    if (static_cast<int>(i) == index) continue;
    const Blob& b = blobs[i];
    const double a = std::min(b.box.size.width, b.box.size.height), c = std::max(b.box.size.width, b.box.size.height);
    if (a < 0.6 * lo || c > 1.5 * lo || b.pixels < 0.7 * a * c) continue;
    const cv::Point2f d = b.box.center - bar.box.center;
    const double along = d.x * axis.x + d.y * axis.y, across = -d.x * axis.y + d.y * axis.x;
    if (std::fabs(along) > 1.7 * hi || std::fabs(across) > 1.5 * lo) continue;
    squares.push_back(i);
  }
  const bool half = squares.size() >= 2;
  bar.px_per_cm = hi / (half ? 0.5 * options_.bar_length_cm : options_.bar_length_cm);
  squares.push_back(static_cast<size_t>(index));
  std::sort(squares.rbegin(), squares.rend());
  if (half) {  // report the whole bar: the white row and the chequer
    std::vector<cv::Point> pts;
    for (size_t i : squares) pts.insert(pts.end(), blobs[i].contour.begin(), blobs[i].contour.end());
    bar.box = cv::minAreaRect(pts);
  }
  for (size_t i : squares) {
    if (half || i == static_cast<size_t>(index)) blobs.erase(blobs.begin() + static_cast<long>(i));
  }
  // Refine the length from the image: the bar (black and white) is brighter than the cloth
  // around it, so the mean value across the bar's width, along its axis, steps up at both ends.
  const double estimate = bar.px_per_cm * options_.bar_length_cm;
  const double half_width = half ? lo : 0.5 * lo;  // the bar is 2 cm wide; the white row 1 cm
  const cv::Point2f across(-axis.y, axis.x);
  const cv::Point2f centre = bar.box.center;
  const int reach = static_cast<int>(1.5 * estimate);
  std::vector<double> profile(2 * reach + 1, 0.0);
  for (int t = -reach; t <= reach; ++t) {
    double sum = 0.0;
    int n = 0;
    for (double k = -0.8 * half_width; k <= 0.8 * half_width; k += 1.0) {
      const cv::Point2f p = centre + static_cast<float>(t) * axis + static_cast<float>(k) * across;
      const int x = cvRound(p.x), y = cvRound(p.y);
      if (x < 0 || y < 0 || x >= hsv.cols || y >= hsv.rows) continue;
      sum += hsv.at<cv::Vec3b>(y, x)[2];
      ++n;
    }
    profile[t + reach] = n ? sum / n : 0.0;
  }
  std::vector<double> inside, outside;
  for (int t = -reach; t <= reach; ++t) {
    if (std::abs(t) < 0.3 * estimate) inside.push_back(profile[t + reach]);
    if (std::abs(t) > 0.7 * estimate) outside.push_back(profile[t + reach]);
  }
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  if (!inside.empty() && !outside.empty()) {
    const double level = 0.5 * (median(inside) + median(outside));
    // walk out from the middle of the bar to the first crossing on each side (sub-pixel)
    int mid = 0;  // the bar position nearest the box centre
    for (int d = 0; d <= reach; ++d) {
      if (profile[reach + d] > level) {
        mid = d;
        break;
      }
      if (profile[reach - d] > level) {
        mid = -d;
        break;
      }
    }
    auto edge = [&](int dir) {
      for (int t = mid; std::abs(t + dir) <= reach; t += dir) {
        const double a = profile[t + reach], b = profile[t + dir + reach];
        if (a > level && b <= level) return t + dir * (a - level) / (a - b);
      }
      return static_cast<double>(dir * reach);
    };
    const double length = edge(+1) - edge(-1);
    if (length > 0.8 * estimate && length < 1.25 * estimate) bar.px_per_cm = length / options_.bar_length_cm;
  }
  return bar;
}

namespace {
/// True if the masks of a and b come within `gap` pixels.
bool within(const Blob& a, const Blob& b, int gap) {
  const cv::Rect ra(a.bounds.x - gap, a.bounds.y - gap, a.bounds.width + 2 * gap, a.bounds.height + 2 * gap);
  const cv::Rect both = ra & b.bounds;
  if (both.empty()) return false;
  cv::Mat grown = cv::Mat::zeros(ra.size(), CV_8U);
  a.mask.copyTo(grown(cv::Rect(gap, gap, a.bounds.width, a.bounds.height)));
  cv::dilate(grown, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * gap + 1, 2 * gap + 1)));
  const cv::Mat ga = grown(cv::Rect(both.tl() - ra.tl(), both.size()));
  const cv::Mat gb = b.mask(cv::Rect(both.tl() - b.bounds.tl(), both.size()));
  return cv::countNonZero(ga & gb) > 0;
}
}  // namespace

void PhotoSegmenter::mergeFragments(std::vector<Blob>& blobs, const cv::Size& size) const {
  // pieces of one sherd cut apart by dark glaze or paint: a much smaller blob close to a larger one
  // (smaller than any sherd, or a tenth of its neighbour, within 2 % of the photo's width)
  const int far = std::max(4, size.width / 50);
  const double tiny = 0.025 * size.width;
  bool merged = true;
  while (merged) {
    merged = false;
    for (size_t i = 0; i < blobs.size() && !merged; ++i) {
      for (size_t j = 0; j < blobs.size() && !merged; ++j) {
        if (i == j) continue;
        const double ratio = static_cast<double>(blobs[i].pixels) / blobs[j].pixels;
        if (ratio >= 0.5) continue;
        const double side = std::max(blobs[i].box.size.width, blobs[i].box.size.height);
        if (!(ratio < 0.15 || side < tiny) || !within(blobs[i], blobs[j], far)) continue;
        const cv::Rect all = blobs[i].bounds | blobs[j].bounds;
        const cv::Rect canvas =
            cv::Rect(all.x - far, all.y - far, all.width + 2 * far, all.height + 2 * far) & cv::Rect(cv::Point(0, 0), size);
        cv::Mat m = cv::Mat::zeros(canvas.size(), CV_8U);
        for (size_t k : {i, j}) blobs[k].mask.copyTo(m(cv::Rect(blobs[k].bounds.tl() - canvas.tl(), blobs[k].bounds.size())), blobs[k].mask);
        cv::morphologyEx(m, m, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * far + 1, 2 * far + 1)));
        Blob b = SherdSegmenter::blobOf(m, canvas.tl());
        if (b.contour.empty()) continue;
        blobs[j] = std::move(b);
        blobs.erase(blobs.begin() + static_cast<long>(i));
        merged = true;
      }
    }
  }
}

namespace {
// Seam splitting (photos only; the station detector has depth). Measured on the three real
// photos: the two edge-to-edge pairs (img114, img071) score 42 and 45 grey levels of black-hat
// along their crack and split into halves of solidity 0.95-0.96; no single sherd gives two
// halves both above 0.92.
constexpr double kSeamSolidityBelow = 0.9;   // only blobs this far from convex are looked at
constexpr double kSeamMinDefect = 0.15;      // deepest concavity, x sqrt(area)
constexpr double kSeamMinLength = 0.3;       // cut length, x sqrt(area)
constexpr double kSeamMinContrast = 35.0;    // mean black-hat along the cut, grey levels
constexpr double kSeamMinPart = 0.2;         // each half, x the blob's area
constexpr double kSeamHalfSolidity = 0.93;   // each half must be this convex

double solidity(const std::vector<cv::Point>& c) {
  std::vector<cv::Point> hull;
  cv::convexHull(c, hull);
  const double h = cv::contourArea(hull);
  return h > 0 ? cv::contourArea(c) / h : 1.0;
}
}  // namespace

void PhotoSegmenter::splitAtSeams(std::vector<Blob>& blobs, const cv::Mat& rgb) const {
  cv::Mat blackhat;  // thin dark lines, computed only if some blob needs it
  std::vector<Blob> out;
  for (Blob& b : blobs) {
    const double area = cv::contourArea(b.contour);
    std::vector<int> hull;
    cv::convexHull(b.contour, hull, false, false);
    std::vector<cv::Vec4i> defects;
    if (hull.size() >= 3 && solidity(b.contour) < kSeamSolidityBelow) {
      std::sort(hull.begin(), hull.end());  // convexityDefects wants a monotonic hull
      try {
        cv::convexityDefects(b.contour, hull, defects);
      } catch (const cv::Exception&) {  // self-intersecting contour: leave the blob as it is
        defects.clear();
      }
    }
    const auto deepest = std::max_element(defects.begin(), defects.end(),
                                          [](const cv::Vec4i& x, const cv::Vec4i& y) { return x[3] < y[3]; });
    const double side = std::sqrt(area);
    if (deepest == defects.end() || (*deepest)[3] / 256.0 < kSeamMinDefect * side) {
      out.push_back(std::move(b));
      continue;
    }
    if (blackhat.empty()) {
      cv::Mat grey;
      cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
      cv::morphologyEx(grey, blackhat, cv::MORPH_BLACKHAT, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
    }
    cv::Mat inside;
    cv::erode(b.mask, inside, cv::Mat::ones(3, 3, CV_8U));
    const cv::Point p = b.contour[(*deepest)[2]];
    double best = -1.0;
    cv::Point best_q;
    for (size_t k = 0; k < b.contour.size(); k += 2) {
      const cv::Point q = b.contour[k];
      const double length = cv::norm(q - p);
      if (length < kSeamMinLength * side) continue;
      const int n = static_cast<int>(length);
      double sum = 0.0;
      int used = 0, outside = 0;
      for (int i = 3; i <= n - 3; ++i) {  // the cut's ends lie on the edge
        const double t = static_cast<double>(i) / n;
        const cv::Point s(cvRound(p.x + t * (q.x - p.x)), cvRound(p.y + t * (q.y - p.y)));
        if (!inside.at<uint8_t>(s - b.bounds.tl())) ++outside;
        sum += blackhat.at<uint8_t>(s);
        ++used;
      }
      if (used < 5 || outside > 0.05 * used) continue;  // the cut must run through the blob
      if (sum / used > best) {
        best = sum / used;
        best_q = q;
      }
    }
    std::vector<Blob> halves;
    if (best >= kSeamMinContrast) {
      cv::Mat cut = b.mask.clone();
      cv::line(cut, p - b.bounds.tl(), best_q - b.bounds.tl(), cv::Scalar(0), 2);
      cv::Mat labels, stats, centroids;
      const int n = cv::connectedComponentsWithStats(cut, labels, stats, centroids, 4, CV_32S);
      for (int i = 1; i < n; ++i) {
        if (stats.at<int>(i, cv::CC_STAT_AREA) < kSeamMinPart * area) continue;
        Blob half = SherdSegmenter::blobOf(labels == i, b.bounds.tl());
        if (!half.contour.empty() && solidity(half.contour) >= kSeamHalfSolidity) halves.push_back(std::move(half));
      }
    }
    if (halves.size() == 2) {
      for (Blob& h : halves) out.push_back(std::move(h));
    } else {
      out.push_back(std::move(b));
    }
  }
  blobs = std::move(out);
}

PhotoResult PhotoSegmenter::segment(const cv::Mat& rgb, const cv::Mat& background) const {
  PhotoResult r;
  r.foreground = foreground(rgb, background);
  SegmentationOptions o;
  o.min_side_px = options_.min_side_fraction * rgb.cols;
  o.max_side_px = options_.max_side_fraction * std::max(rgb.cols, rgb.rows);
  o.border_margin = 2;
  o.split_min_neck = options_.split_min_neck;
  std::vector<Blob> blobs = SherdSegmenter().blobs(r.foreground, o);
  r.bar = findBar(rgb, blobs);
  splitAtSeams(blobs, rgb);
  mergeFragments(blobs, rgb.size());
  const double mm_per_px = r.bar.found ? 10.0 / r.bar.px_per_cm : 0.0;
  for (Blob& b : blobs) {
    PhotoSherd s;
    const cv::Scalar c = cv::mean(rgb(b.bounds), b.mask);
    s.colour = cv::Vec3d(c[0], c[1], c[2]) / 255.0;
    s.length_mm = std::max(b.box.size.width, b.box.size.height) * mm_per_px;
    s.width_mm = std::min(b.box.size.width, b.box.size.height) * mm_per_px;
    s.area_mm2 = b.pixels * mm_per_px * mm_per_px;
    s.blob = std::move(b);
    r.sherds.push_back(std::move(s));
  }
  return r;
}

}  // namespace rascal_perception
