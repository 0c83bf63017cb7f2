// findScaleBar on the real photos (px/cm read by hand from the chequer pitch, photos_truth.json),
// on bars rendered at any rotation and scale over textured cloth with a shadow across them, and on
// images without a bar.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "rascal_perception/ScaleBarFinder.hpp"

using namespace rascal_perception;

namespace {

const std::string kPhotos = std::string(RASCAL_PERCEPTION_PHOTOS) + "/";

cv::Mat photo(const std::string& name) {
  cv::Mat bgr = cv::imread(kPhotos + name, cv::IMREAD_COLOR);
  cv::Mat rgb;
  if (!bgr.empty()) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

/// Photos whose truth has a px/cm, with it.
std::vector<std::pair<std::string, double>> photosWithTruth() {
  cv::FileStorage fs(kPhotos + "photos_truth.json", cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);
  std::vector<std::pair<std::string, double>> out;
  for (const cv::FileNode& n : fs.root()) {
    if (!n["px_per_cm"].empty()) out.emplace_back(n.name(), (double)n["px_per_cm"]);
  }
  return out;
}

/// Cloth: a base grey with blurred noise (weave, lint) and a slow brightness change.
cv::Mat cloth(cv::Size size, double base, std::mt19937& rng) {
  cv::Mat noise(size, CV_32F);
  cv::randn(noise, 0, 1);
  cv::Mat fine, coarse;
  cv::GaussianBlur(noise, fine, {0, 0}, 1.5);
  cv::GaussianBlur(noise, coarse, {0, 0}, 25);
  cv::Mat grey = base + 30 * fine + 300 * coarse;
  std::uniform_real_distribution<double> tint(0.85, 1.15);
  std::vector<cv::Mat> ch{grey * tint(rng), grey * tint(rng), grey * tint(rng)};
  cv::Mat rgb;
  cv::merge(ch, rgb);
  return rgb;
}

struct Rendered {
  cv::Mat rgb;
  double px_per_cm;
};

/// The bar at `px_per_cm` and `angle_deg` centred at `centre`, over cloth; a shadow (down to 45 %
/// of the light) across part of the image; blur, noise, JPEG. Drawn at 4x and shrunk (anti-alias).
Rendered renderBar(cv::Size size, double base, double px_per_cm, double angle_deg, cv::Point2d centre,
                   std::mt19937& rng) {
  const int k = 4;
  cv::Mat img = cloth(size, base, rng);
  cv::Mat big;
  cv::resize(img, big, size * k, 0, 0, cv::INTER_LINEAR);
  const double c = std::cos(angle_deg * CV_PI / 180), s = std::sin(angle_deg * CV_PI / 180);
  auto at = [&](double x_cm, double y_cm) {  // bar coordinates (0..10, 0..2 cm) to 4x image pixels, 1/16 px
    const double x = (x_cm - 5) * px_per_cm, y = (y_cm - 1) * px_per_cm;
    return cv::Point((int)std::lround(16 * k * (centre.x + c * x - s * y)),
                     (int)std::lround(16 * k * (centre.y + s * x + c * y)));
  };
  auto cell = [&](double x0, double y0, double x1, double y1, double v) {
    const std::vector<cv::Point> poly{at(x0, y0), at(x1, y0), at(x1, y1), at(x0, y1)};
    cv::fillPoly(big, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(v, v, 0.97 * v), cv::LINE_8, 4);
  };
  const double white = 235, black = 35;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 2; ++j) cell(i, j, i + 1, j + 1, (i + j) % 2 ? black : white);
  }
  cell(5, 0, 10, 1, black);
  cell(5, 1, 10, 2, white);
  cv::resize(big, img, size, 0, 0, cv::INTER_AREA);
  // shadow: light falls off linearly across a random line near the bar
  std::uniform_real_distribution<double> u(0, 1);
  const double sa = 2 * CV_PI * u(rng);
  const double sx = std::cos(sa), sy = std::sin(sa), width = 4 * px_per_cm;
  cv::Mat light(size, CV_32F);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const double t = ((x - centre.x) * sx + (y - centre.y) * sy) / width;
      light.at<float>(y, x) = (float)(1.0 - 0.55 * std::clamp(t + 0.5, 0.0, 1.0));
    }
  }
  std::vector<cv::Mat> ch;
  cv::split(img, ch);
  for (cv::Mat& m : ch) m = m.mul(light);
  cv::merge(ch, img);
  cv::GaussianBlur(img, img, {0, 0}, 0.6 + 0.6 * u(rng));
  cv::Mat noise(size, CV_32FC3);
  cv::randn(noise, 0, 4);
  img += noise;
  cv::Mat out;
  img.convertTo(out, CV_8UC3);
  std::vector<uchar> jpg;
  cv::imencode(".jpg", out, jpg, {cv::IMWRITE_JPEG_QUALITY, 80});
  return {cv::imdecode(jpg, cv::IMREAD_COLOR), px_per_cm};  // channel order does not matter here
}

}  // namespace

TEST(ScaleBarFinder, EveryPhotoWithinTwoPercent) {
  const auto photos = photosWithTruth();
  ASSERT_GE(photos.size(), 20u);
  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);  // the time printed is one core's
  double worst_ms = 0;
  for (const auto& [name, truth] : photos) {
    const cv::Mat rgb = photo(name);
    EXPECT_FALSE(rgb.empty()) << name;
    if (rgb.empty()) continue;
    const auto t0 = std::chrono::steady_clock::now();
    const ScaleBar bar = findScaleBar(rgb);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    worst_ms = std::max(worst_ms, ms);
    std::printf("%-36s truth %6.2f found %d %6.2f (%+5.1f %%) ends %6.2f squares %d spread %.3f %5.1f ms %s\n",
                name.c_str(), truth, bar.found, bar.px_per_cm, 100 * (bar.px_per_cm / truth - 1), bar.ends_px_per_cm,
                bar.squares, bar.pitch_spread, ms, bar.doubt.c_str());
    EXPECT_TRUE(bar.found) << name;
    EXPECT_NEAR(bar.px_per_cm, truth, 0.02 * truth) << name;
    // the box covers the bar: 10 x 2 cm at the found scale
    EXPECT_NEAR(bar.box.size.width, 10 * bar.px_per_cm, 0.05 * 10 * bar.px_per_cm) << name;
  }
  cv::setNumThreads(threads);
  std::printf("slowest photo %.1f ms (one thread)\n", worst_ms);
}

TEST(ScaleBarFinder, RenderedBarsAtAnyRotationScaleAndShadow) {
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> u(0, 1);
  int n = 0, within = 0, doubtful = 0;
  double worst = 0;
  for (int k = 0; k < 24; ++k) {
    const double scale = 8 + 22 * u(rng), angle = 360 * u(rng), base = k % 2 ? 45 : 110;
    const cv::Size size(640, 480);
    const cv::Point2d centre(size.width / 2 + 100 * (u(rng) - 0.5), size.height / 2 + 80 * (u(rng) - 0.5));
    const Rendered r = renderBar(size, base, scale, angle, centre, rng);
    const ScaleBar bar = findScaleBar(r.rgb);
    ++n;
    const double err = bar.found ? bar.px_per_cm / scale - 1 : 1;
    within += std::fabs(err) < 0.02;
    doubtful += bar.found && !bar.doubt.empty();
    worst = std::max(worst, std::fabs(err));
    EXPECT_TRUE(bar.found) << "scale " << scale << " angle " << angle << " cloth " << base;
    EXPECT_NEAR(bar.px_per_cm, scale, 0.02 * scale) << "angle " << angle << " cloth " << base;
    if (bar.found) {
      EXPECT_LT(cv::norm(cv::Point2d(bar.box.center) - centre), 0.5 * scale) << "angle " << angle;
    }
  }
  std::printf("rendered bars: %d of %d within 2 %%, worst %.2f %%, %d doubtful\n", within, n, 100 * worst, doubtful);
}

TEST(ScaleBarFinder, NothingWithoutABar) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (const double base : {40.0, 110.0}) {
    // cloth with sherd-like blobs and a few bright squares that are not a chequer
    cv::Mat img = cloth({640, 480}, base, rng);
    for (int k = 0; k < 12; ++k) {
      const cv::Point c((int)(40 + 560 * u(rng)), (int)(40 + 400 * u(rng)));
      cv::ellipse(img, c, cv::Size((int)(10 + 30 * u(rng)), (int)(8 + 20 * u(rng))), 360 * u(rng), 0, 360,
                  cv::Scalar(150 + 80 * u(rng), 120 + 60 * u(rng), 90), cv::FILLED);
    }
    for (int k = 0; k < 3; ++k) {
      const cv::Rect square((int)(50 + 500 * u(rng)), (int)(50 + 350 * u(rng)), 14, 14);
      cv::rectangle(img, square, cv::Scalar(230, 230, 230), cv::FILLED);
    }
    cv::Mat out;
    img.convertTo(out, CV_8UC3);
    EXPECT_FALSE(findScaleBar(out).found) << "cloth " << base;
  }
  // a mosaic of random tiles at a bar's pitch: squares on a lattice, tones at random (at worst a
  // doubtful bar)
  cv::Mat tiles(40, 54, CV_8UC3), mosaic;
  cv::randu(tiles, 0, 255);
  cv::resize(tiles, mosaic, {648, 480}, 0, 0, cv::INTER_NEAREST);
  const ScaleBar lucky = findScaleBar(mosaic);
  EXPECT_TRUE(!lucky.found || !lucky.doubt.empty()) << lucky.px_per_cm;
  // a plain image (the simulator's flat colours)
  EXPECT_FALSE(findScaleBar(cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 90, 140))).found);
  EXPECT_FALSE(findScaleBar(cv::Mat()).found);
}

TEST(ScaleBarFinder, RealPhotosWithTheBarPaintedOut) {
  // the 8 photos the finder was tuned on (the variants share their bars)
  for (const std::string name : {"img005DSC02101.jpg", "img040DSC02176.jpg", "img048DSC02186.jpg",
                                 "img071DSC02209.jpg", "img114SG101831.jpg", "img129SG101853.jpg",
                                 "img149SG101882.jpg", "img171SG101906.jpg"}) {
    cv::Mat rgb = photo(name);
    const ScaleBar bar = findScaleBar(rgb);
    ASSERT_TRUE(bar.found) << name;
    // paint the bar (and 1 cm around it) with the cloth's colour, from a ring around it
    cv::RotatedRect grown = bar.box;
    grown.size += cv::Size2f(2 * (float)bar.px_per_cm, 2 * (float)bar.px_per_cm);
    cv::RotatedRect ring = grown;
    ring.size += cv::Size2f(2 * (float)bar.px_per_cm, 2 * (float)bar.px_per_cm);
    std::vector<cv::Point2f> p(4), q(4);
    grown.points(p.data());
    ring.points(q.data());
    cv::Mat inner = cv::Mat::zeros(rgb.size(), CV_8U), outer = cv::Mat::zeros(rgb.size(), CV_8U);
    cv::fillConvexPoly(inner, std::vector<cv::Point>(p.begin(), p.end()), 255);
    cv::fillConvexPoly(outer, std::vector<cv::Point>(q.begin(), q.end()), 255);
    const cv::Scalar colour = cv::mean(rgb, outer & ~inner);
    rgb.setTo(colour, inner);
    const ScaleBar none = findScaleBar(rgb);
    EXPECT_FALSE(none.found) << name << ": " << none.px_per_cm << " px/cm at " << none.box.center;
  }
}
