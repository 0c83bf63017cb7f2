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
        std::vector<std::vector<cv::Point>> contours;
        cv::findContours(m, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE, canvas.tl());
        if (contours.empty()) continue;
        size_t best = 0;
        for (size_t k = 1; k < contours.size(); ++k) {
          if (cv::contourArea(contours[k]) > cv::contourArea(contours[best])) best = k;
        }
        Blob b;
        b.contour = std::move(contours[best]);
        b.bounds = cv::boundingRect(b.contour);
        b.mask = cv::Mat::zeros(b.bounds.size(), CV_8U);
        cv::drawContours(b.mask, std::vector<std::vector<cv::Point>>{b.contour}, 0, cv::Scalar(255), cv::FILLED,
                         cv::LINE_8, cv::noArray(), 0, -b.bounds.tl());
        b.pixels = cv::countNonZero(b.mask);
        b.box = cv::minAreaRect(b.contour);
        blobs[j] = std::move(b);
        blobs.erase(blobs.begin() + static_cast<long>(i));
        merged = true;
      }
    }
  }
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
