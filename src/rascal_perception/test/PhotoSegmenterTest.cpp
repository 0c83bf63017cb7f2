// PhotoSegmenter on the real sherd photos (shared/data/sherds/photos: dark cloth, 10 cm bar with a
// chequered half). The sherd centres and the px/cm below were read by hand:
//  - centres: from the photo viewed at full size (approximate, +-10 px);
//  - px/cm: the bar cropped and magnified 4x with a pixel ruler (ticks every 10 px). img005: bar
//    edges at x = 407 and 633 (226 px / 10 cm), chequer edges every 22.5 px -> 22.55 px/cm;
//    img114: bar edges at x = 443.75 and 635 (191.25 px), chequer edges every 19.15 px -> 19.1 px/cm;
//    img071 (6x crop, ticks every 5 px): bar edges at x = 385.8 and 514.2 (128.4 px), chequer
//    edges every 12.83 px -> 12.84 px/cm.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "rascal_perception/PhotoSegmenter.hpp"

using namespace rascal_perception;

namespace {
cv::Mat photo(const std::string& name) {
  cv::Mat bgr = cv::imread(std::string(RASCAL_PERCEPTION_PHOTOS) + "/" + name, cv::IMREAD_COLOR);
  cv::Mat rgb;
  if (!bgr.empty()) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

/// How many detections cover the hand-read centre (contour contains it, or box centre within 25 px).
int covering(const PhotoResult& r, const cv::Point2f& c) {
  int n = 0;
  for (const PhotoSherd& s : r.sherds) {
    if (cv::pointPolygonTest(s.blob.contour, c, false) >= 0 || cv::norm(s.blob.box.center - c) < 25) ++n;
  }
  return n;
}

void check(const std::string& name, const std::vector<cv::Point2f>& centres, double px_per_cm) {
  const cv::Mat rgb = photo(name);
  ASSERT_FALSE(rgb.empty()) << name;
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
  ASSERT_TRUE(r.bar.found) << name;
  EXPECT_NEAR(r.bar.px_per_cm, px_per_cm, 0.03 * px_per_cm) << name;
  EXPECT_EQ(r.sherds.size(), centres.size()) << name;
  for (size_t i = 0; i < centres.size(); ++i) {
    EXPECT_EQ(covering(r, centres[i]), 1) << name << ": sherd at " << centres[i];
  }
  // the bar is not a sherd
  std::vector<cv::Point2f> bar(4);
  r.bar.box.points(bar.data());
  for (const PhotoSherd& s : r.sherds) EXPECT_LT(cv::pointPolygonTest(bar, s.blob.box.center, false), 0) << name;
}
}  // namespace

TEST(PhotoSegmenter, MaiolicaPhotoEverySherdOnceAndTheBar) {
  check("img005DSC02101.jpg",
        {{443, 128}, {587, 130}, {162, 273}, {215, 242}, {347, 230}, {500, 220}, {648, 213}, {742, 207}, {897, 230},
         {155, 490}, {250, 460}, {380, 465}, {675, 440}, {888, 385}, {880, 452}, {320, 640}, {515, 617}, {708, 615}},
        22.55);
}

const std::vector<cv::Point2f> kSgraffito{{285, 160}, {415, 185}, {525, 192}, {600, 175}, {750, 200},
                                          {275, 298}, {382, 290}, {494, 293}, {620, 297}, {233, 430},
                                          {288, 428}, {423, 420}, {600, 415}, {762, 368}, {777, 425}};

TEST(PhotoSegmenter, SgraffitoPhotoEverySherdOnceAndTheBar) {
  // the last two lie edge to edge: no neck for the distance transform, split at their crack
  check("img114SG101831.jpg", kSgraffito, 19.1);
}

TEST(PhotoSegmenter, TwoPiecesLyingEdgeToEdgeAreTwoSherds) {
  // img071: two glazed pieces with a straight crack between them, read by hand at about
  // (840, 463) and (887, 503)
  const cv::Mat rgb = photo("img071DSC02209.jpg");
  ASSERT_FALSE(rgb.empty());
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
  EXPECT_EQ(covering(r, {840, 463}), 1);
  EXPECT_EQ(covering(r, {887, 503}), 1);
  for (const PhotoSherd& s : r.sherds) {
    const bool both = cv::pointPolygonTest(s.blob.contour, cv::Point2f(840, 463), false) >= 0 &&
                      cv::pointPolygonTest(s.blob.contour, cv::Point2f(887, 503), false) >= 0;
    EXPECT_FALSE(both) << "one detection covers both pieces";
  }
}

TEST(PhotoSegmenter, SmallBarWhoseChequerMergesWithItsWhiteRow) {
  // 50 sherds and a bar only 128 px long: its white squares and row touch after the closing
  const cv::Mat rgb = photo("img071DSC02209.jpg");
  ASSERT_FALSE(rgb.empty());
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
  ASSERT_TRUE(r.bar.found);
  EXPECT_NEAR(r.bar.px_per_cm, 12.84, 0.03 * 12.84);
}

TEST(PhotoSegmenter, NoBarNoScale) {
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(40, 40, 45));
  cv::circle(img, cv::Point(200, 150), 40, cv::Scalar(200, 150, 110), cv::FILLED);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  EXPECT_FALSE(r.bar.found);
  ASSERT_EQ(r.sherds.size(), 1u);
  EXPECT_EQ(r.sherds[0].length_mm, 0.0);
}
