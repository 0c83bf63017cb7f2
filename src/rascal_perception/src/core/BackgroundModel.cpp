#include "rascal_perception/BackgroundModel.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "StoredFields.hpp"

namespace rascal_perception {

namespace {
constexpr double kTwoPi = 6.283185307179586;
constexpr double kValueWeight = 0.1;  ///< value is nearly ignored by the clustering

double hueDistance(double a, double b) {
  double d = std::fabs(a - b);
  return d > 0.5 ? 1.0 - d : d;
}
}  // namespace

void BackgroundModel::learn(const cv::Mat& rgb, const BackgroundOptions& options, const cv::Mat& ignore) {
  if (rgb.empty() || rgb.type() != CV_8UC3) {
    throw std::invalid_argument("BackgroundModel::learn: need a CV_8UC3 RGB image");
  }
  if (options.clusters < 1 || options.clusters > 8) {
    throw std::invalid_argument("BackgroundModel::learn: clusters must be 1..8");
  }
  options_ = options;
  cv::Mat hsv;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV_FULL);
  cluster(hsv, ignore);

  // where each cluster was seen (grown), and what matched nothing: the fixtures
  const int vmin = static_cast<int>(std::lround(options_.min_value * 255.0));
  cv::Mat bits(hsv.size(), CV_8U), fixture(hsv.size(), CV_8U);
  for (int y = 0; y < hsv.rows; ++y) {
    const cv::Vec3b* p = hsv.ptr<cv::Vec3b>(y);
    uint8_t* b = bits.ptr<uint8_t>(y);
    uint8_t* f = fixture.ptr<uint8_t>(y);
    for (int x = 0; x < hsv.cols; ++x) {
      const bool dark = p[x][2] < vmin;
      b[x] = dark ? 0 : match(p[x][0], p[x][1]);
      f[x] = (!dark && b[x] == 0) ? 255 : 0;
    }
  }
  if (!ignore.empty()) fixture.setTo(0, ignore);
  cv::morphologyEx(fixture, fixture_, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  seen_ = cv::Mat::zeros(hsv.size(), CV_8U);
  const int r = std::max(0, options_.prior_dilation_px);
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
  for (size_t c = 0; c < clusters_.size(); ++c) {
    cv::Mat m = (bits & cv::Scalar(1 << c)) != 0;
    if (r > 0) cv::dilate(m, m, kernel);
    cv::bitwise_or(seen_, cv::Scalar(1 << c), seen_, m);
  }
  // dark calibration pixels say nothing: any cluster may appear there
  seen_.setTo(0xFF, (bits == 0) & (fixture_ == 0));
}

void BackgroundModel::refresh(const cv::Mat& rgb, const cv::Mat& ignore) {
  if (!ready()) throw std::logic_error("BackgroundModel::refresh: learn() first");
  cv::Mat hsv;
  cv::cvtColor(rgb, hsv, cv::COLOR_RGB2HSV_FULL);
  const std::vector<BackgroundCluster> before = clusters_;
  cluster(hsv, ignore);
  // carry the seen-map over: each old cluster's bit goes to the new cluster nearest in chroma;
  // a new cluster that is nobody's nearest may appear anywhere
  auto chroma = [](const BackgroundCluster& c) {
    return cv::Point2d(c.saturation * std::cos(kTwoPi * c.hue), c.saturation * std::sin(kTwoPi * c.hue));
  };
  std::vector<int> to(before.size(), 0);
  uint8_t claimed = 0;
  for (size_t o = 0; o < before.size(); ++o) {
    double best = 1e9;
    for (size_t n = 0; n < clusters_.size(); ++n) {
      const double d = cv::norm(chroma(before[o]) - chroma(clusters_[n]));
      if (d < best) {
        best = d;
        to[o] = static_cast<int>(n);
      }
    }
    claimed |= static_cast<uint8_t>(1 << to[o]);
  }
  cv::Mat seen = cv::Mat::zeros(seen_.size(), CV_8U);
  for (size_t o = 0; o < before.size(); ++o) {
    cv::bitwise_or(seen, cv::Scalar(1 << to[o]), seen, (seen_ & cv::Scalar(1 << o)) != 0);
  }
  uint8_t everywhere = 0;
  for (size_t n = 0; n < clusters_.size(); ++n) {
    if (!(claimed & (1 << n))) everywhere |= static_cast<uint8_t>(1 << n);
  }
  if (everywhere) seen |= cv::Scalar(everywhere);
  seen.setTo(0xFF, seen_ == 0xFF);
  seen_ = seen;
}

void BackgroundModel::cluster(const cv::Mat& hsv, const cv::Mat& ignore) {
  const int vmin = static_cast<int>(std::lround(options_.min_value * 255.0));
  const int step = std::max(1, static_cast<int>(std::sqrt(hsv.total() / 20000.0)));
  std::vector<cv::Vec3f> samples;
  std::vector<cv::Vec3f> hsv_samples;
  samples.reserve(hsv.total() / (step * step) + 1);
  for (int y = step / 2; y < hsv.rows; y += step) {
    const cv::Vec3b* p = hsv.ptr<cv::Vec3b>(y);
    for (int x = step / 2; x < hsv.cols; x += step) {
      if (p[x][2] < vmin) continue;
      if (!ignore.empty() && ignore.at<uint8_t>(y, x)) continue;
      const float h = p[x][0] / 256.0f, s = p[x][1] / 255.0f, v = p[x][2] / 255.0f;
      samples.emplace_back(s * std::cos(kTwoPi * h), s * std::sin(kTwoPi * h), kValueWeight * v);
      hsv_samples.emplace_back(h, s, v);
    }
  }
  const int k = std::min<int>(options_.clusters, static_cast<int>(samples.size()));
  if (k < 1) throw std::invalid_argument("BackgroundModel::learn: the image is too dark to learn from");
  cv::Mat data(static_cast<int>(samples.size()), 3, CV_32F, samples.data());
  cv::Mat labels, centres;
  const uint64_t saved_rng = cv::theRNG().state;  // seeded k-means, without touching others' RNG
  cv::theRNG().state = options_.seed;
  cv::kmeans(data, k, labels, cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4), 3,
             cv::KMEANS_PP_CENTERS, centres);
  cv::theRNG().state = saved_rng;
  struct Acc { double c = 0, s = 0, sat = 0, v = 0; int n = 0; };
  std::vector<Acc> acc(k);
  for (size_t i = 0; i < hsv_samples.size(); ++i) {
    Acc& a = acc[labels.at<int>(static_cast<int>(i))];
    const cv::Vec3f& q = hsv_samples[i];
    a.c += std::cos(kTwoPi * q[0]);
    a.s += std::sin(kTwoPi * q[0]);
    a.sat += q[1];
    a.v += q[2];
    ++a.n;
  }
  clusters_.clear();
  for (const Acc& a : acc) {
    if (a.n == 0) continue;
    BackgroundCluster c;
    c.fraction = static_cast<double>(a.n) / hsv_samples.size();
    if (c.fraction < options_.min_cluster_fraction) continue;
    double h = std::atan2(a.s, a.c) / kTwoPi;
    c.hue = h < 0 ? h + 1.0 : h;
    c.saturation = a.sat / a.n;
    c.value = a.v / a.n;
    c.grey = c.saturation < options_.grey_saturation;
    clusters_.push_back(c);
  }
  std::sort(clusters_.begin(), clusters_.end(),
            [](const BackgroundCluster& a, const BackgroundCluster& b) { return a.fraction > b.fraction; });
  buildLut();
}

void BackgroundModel::write(cv::FileStorage& fs) const {
  if (!ready()) throw std::logic_error("BackgroundModel::write: no model learnt");
  fs << "options" << "{"
     << "clusters" << options_.clusters << "hue_tolerance" << options_.hue_tolerance << "saturation_tolerance"
     << options_.saturation_tolerance << "min_value" << options_.min_value << "min_cluster_fraction"
     << options_.min_cluster_fraction << "grey_saturation" << options_.grey_saturation << "prior_dilation_px"
     << options_.prior_dilation_px << "seed" << static_cast<int>(options_.seed) << "}";
  fs << "clusters" << "[";
  for (const BackgroundCluster& c : clusters_) {
    fs << "{" << "hue" << c.hue << "saturation" << c.saturation << "value" << c.value << "fraction" << c.fraction
       << "grey" << static_cast<int>(c.grey) << "}";
  }
  fs << "]";
  fs << "seen" << seen_ << "fixture" << fixture_;
}

void BackgroundModel::read(const cv::FileNode& node) {
  const cv::FileNode o = node["options"], cs = node["clusters"];
  if (o.empty() || cs.empty() || !cs.isSeq() || cs.size() < 1 || cs.size() > 8) {
    throw std::invalid_argument("background model: options or 1..8 clusters missing");
  }
  const std::string where = "background model";
  BackgroundOptions options;
  options.clusters = storedInt(o, "clusters", where);
  options.hue_tolerance = storedNumber(o, "hue_tolerance", where);
  options.saturation_tolerance = storedNumber(o, "saturation_tolerance", where);
  options.min_value = storedNumber(o, "min_value", where);
  options.min_cluster_fraction = storedNumber(o, "min_cluster_fraction", where);
  options.grey_saturation = storedNumber(o, "grey_saturation", where);
  options.prior_dilation_px = storedInt(o, "prior_dilation_px", where);
  options.seed = static_cast<unsigned>(storedInt(o, "seed", where));
  std::vector<BackgroundCluster> clusters;
  for (const cv::FileNode c : cs) {
    BackgroundCluster k;
    k.hue = storedNumber(c, "hue", where + " cluster");
    k.saturation = storedNumber(c, "saturation", where + " cluster");
    k.value = storedNumber(c, "value", where + " cluster");
    k.fraction = storedNumber(c, "fraction", where + " cluster");
    k.grey = storedInt(c, "grey", where + " cluster") != 0;
    clusters.push_back(k);
  }
  cv::Mat seen, fixture;
  node["seen"] >> seen;
  node["fixture"] >> fixture;
  if (seen.empty() || seen.type() != CV_8U || fixture.size() != seen.size() || fixture.type() != CV_8U) {
    throw std::invalid_argument("background model: seen-map or fixture mask missing");
  }
  options_ = options;
  clusters_ = clusters;
  seen_ = seen;
  fixture_ = fixture;
  buildLut();
}

void BackgroundModel::buildLut() {
  lut_.assign(256 * 256, 0);
  for (int h = 0; h < 256; ++h) {
    for (int s = 0; s < 256; ++s) {
      uint8_t bits = 0;
      for (size_t c = 0; c < clusters_.size(); ++c) {
        const BackgroundCluster& k = clusters_[c];
        // loose, but in proportion: a pale cluster must not swallow every grey
        const double band = std::min(options_.saturation_tolerance, std::max(0.5 * k.saturation, 0.08));
        if (std::fabs(s / 255.0 - k.saturation) > band) continue;
        if (!k.grey && hueDistance(h / 256.0, k.hue) > options_.hue_tolerance) continue;
        bits |= static_cast<uint8_t>(1 << c);
      }
      lut_[h * 256 + s] = bits;
    }
  }
  // every 6-bit RGB bin's centre through OpenCV's own HSV conversion, then the table above
  cv::Mat centres(64 * 64, 64, CV_8UC3), hsv;
  for (int r = 0; r < 64; ++r) {
    for (int g = 0; g < 64; ++g) {
      cv::Vec3b* row = centres.ptr<cv::Vec3b>(r * 64 + g);
      for (int b = 0; b < 64; ++b) row[b] = cv::Vec3b(static_cast<uint8_t>(4 * r + 2), static_cast<uint8_t>(4 * g + 2), static_cast<uint8_t>(4 * b + 2));
    }
  }
  cv::cvtColor(centres, hsv, cv::COLOR_RGB2HSV_FULL);
  rgb_lut_.resize(64 * 64 * 64);
  for (int i = 0; i < 64 * 64; ++i) {
    const cv::Vec3b* p = hsv.ptr<cv::Vec3b>(i);
    for (int b = 0; b < 64; ++b) rgb_lut_[i * 64 + b] = match(p[b][0], p[b][1]);
  }
}

void BackgroundModel::classify(const cv::Mat& hsv, const cv::Mat& allowed, cv::Mat& background) const {
  if (!ready()) throw std::logic_error("BackgroundModel::classify: no model learnt");
  const int vmin = static_cast<int>(std::lround(options_.min_value * 255.0));
  background.create(hsv.size(), CV_8U);
  const bool any = allowed.empty();
  for (int y = 0; y < hsv.rows; ++y) {
    const cv::Vec3b* p = hsv.ptr<cv::Vec3b>(y);
    const uint8_t* a = any ? nullptr : allowed.ptr<uint8_t>(y);
    uint8_t* o = background.ptr<uint8_t>(y);
    for (int x = 0; x < hsv.cols; ++x) {
      if (p[x][2] < vmin) {
        o[x] = 255;
        continue;
      }
      const uint8_t bits = lut_[p[x][0] * 256 + p[x][1]];
      o[x] = (any ? bits : (bits & a[x])) ? 255 : 0;
    }
  }
}

void BackgroundModel::classifyRgb(const cv::Mat& rgb, const cv::Mat& allowed, cv::Mat& background) const {
  if (!ready()) throw std::logic_error("BackgroundModel::classifyRgb: no model learnt");
  const int vmin = static_cast<int>(std::lround(options_.min_value * 255.0));
  background.create(rgb.size(), CV_8U);
  const uint8_t* lut = rgb_lut_.data();
  const cv::Mat everywhere = allowed.empty() ? cv::Mat(rgb.size(), CV_8U, cv::Scalar(0xFF)) : allowed;
  for (int y = 0; y < rgb.rows; ++y) {
    const uint8_t* p = rgb.ptr<uint8_t>(y);
    const uint8_t* a = everywhere.ptr<uint8_t>(y);
    uint8_t* o = background.ptr<uint8_t>(y);
    for (int x = 0; x < rgb.cols; ++x, p += 3) {
      const int r = p[0], g = p[1], b = p[2];
      const bool dark = r < vmin && g < vmin && b < vmin;
      o[x] = (dark || (lut[((r >> 2) << 12) | ((g >> 2) << 6) | (b >> 2)] & a[x])) ? 255 : 0;
    }
  }
}

}  // namespace rascal_perception
