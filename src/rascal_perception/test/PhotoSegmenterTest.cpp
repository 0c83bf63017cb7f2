// PhotoSegmenter on the real sherd photos (test/data/photos: dark cloth, 10 cm bar with a
// chequered half), against the hand truth in photos_truth.json (count_range per photo). The
// sherd centres below were read by hand from the photo viewed at full size (+-10 px).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "rascal_perception/PhotoSegmenter.hpp"

using namespace rascal_perception;

namespace {
const std::string kPhotos = RASCAL_PERCEPTION_PHOTOS;

cv::Mat photo(const std::string& name) {
  cv::Mat bgr = cv::imread(kPhotos + "/" + name, cv::IMREAD_COLOR);
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

void check(const std::string& name, const std::vector<cv::Point2f>& centres) {
  const cv::Mat rgb = photo(name);
  ASSERT_FALSE(rgb.empty()) << name;
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
  for (size_t i = 0; i < centres.size(); ++i) {
    EXPECT_EQ(covering(r, centres[i]), 1) << name << ": sherd at " << centres[i];
  }
  if (!r.bar.found) return;  // the bar itself is ScaleBarFinder's test
  std::vector<cv::Point2f> bar(4);
  r.bar.box.points(bar.data());
  for (const PhotoSherd& s : r.sherds) EXPECT_LT(cv::pointPolygonTest(bar, s.blob.box.center, false), 0) << name;
}

// Photos whose count is still outside the hand range with the one set of defaults, and why.
// The test reports them (count and range) but does not fail on them; the lead decides.
const std::set<std::string> kKnownFailures = {
    // A camera original with the room around the black sheet (flagged background-doubtful):
    // the floor and the door beside the sheet are left out, but among the crowded small
    // sherds two merge (118 for 119-123; the cropped img129 gives 120 of 119-121). Which of
    // these marginal photos passes has moved with every change to the cloth model: counted,
    // not tuned. (img149_orig, a pair laid edge to edge, is split since the notch-to-notch cut.)
    "img129SG101853_orig.jpg",
};
}  // namespace

TEST(PhotoSegmenter, MaiolicaPhotoEverySherdOnce) {
  check("img005DSC02101.jpg",
        {{443, 128}, {587, 130}, {162, 273}, {215, 242}, {347, 230}, {500, 220}, {648, 213}, {742, 207}, {897, 230},
         {155, 490}, {250, 460}, {380, 465}, {675, 440}, {888, 385}, {880, 452}, {320, 640}, {515, 617}, {708, 615}});
}

TEST(PhotoSegmenter, SgraffitoPhotoEverySherdOnce) {
  // the last two lie edge to edge: no neck for the distance transform, split at their crack
  check("img114SG101831.jpg", {{285, 160}, {415, 185}, {525, 192}, {600, 175}, {750, 200},
                               {275, 298}, {382, 290}, {494, 293}, {620, 297}, {233, 430},
                               {288, 428}, {423, 420}, {600, 415}, {762, 368}, {777, 425}});
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

TEST(PhotoSegmenter, APairLaidEdgeToEdgeInANearlyConvexOutlineIsTwoSherds) {
  // img149's camera original: two pieces of a rim laid edge to edge, the seam a 1-2 px shadow
  // from a notch at the top to one at the bottom (about x 471-474, y 200-265); their outline
  // together is nearly convex (solidity 0.90), read by hand at about (425, 235) and (525, 230)
  const cv::Mat rgb = photo("img149SG101882_orig.jpg");
  ASSERT_FALSE(rgb.empty());
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
  EXPECT_EQ(covering(r, {425, 235}), 1);
  EXPECT_EQ(covering(r, {525, 230}), 1);
}

/// Two 80 px sherd-coloured squares on dark cloth side by side, the right one 15 px lower: one
/// outline (solidity 0.91, no neck) with a shallow notch above and below where they meet,
/// joined by a 2 px line `darker` grey levels below the sherd: a seam between two pieces (as
/// dark as the cloth or darker: the gap, a shadow), or a painted line on one.
cv::Mat steppedPair(int darker) {
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(40, 40, 45));
  const cv::Scalar sherd(200, 160, 120);
  cv::rectangle(img, cv::Rect(120, 110, 80, 80), sherd, cv::FILLED);
  cv::rectangle(img, cv::Rect(200, 125, 80, 80), sherd, cv::FILLED);
  cv::line(img, {200, 125}, {200, 190}, sherd - cv::Scalar::all(darker), 2);
  return img;
}

TEST(PhotoSegmenter, ANearlyConvexOutlineIsCutOnlyAlongADarkSeamFromNotchToNotch) {
  const PhotoSegmenter segmenter{PhotoSegmenter::Options()};
  const PhotoResult seam = segmenter.segment(steppedPair(150));
  ASSERT_EQ(seam.sherds.size(), 2u) << "a dark seam joining the two notches splits the pair";
  EXPECT_NEAR(std::min(seam.sherds[0].blob.box.center.x, seam.sherds[1].blob.box.center.x), 160, 4);
  EXPECT_NEAR(std::max(seam.sherds[0].blob.box.center.x, seam.sherds[1].blob.box.center.x), 240, 4);
  // a line as dark as the black-hat asks but lighter than the cloth lies on the sherd (paint,
  // an incised line), and a fainter one (a painted band's edge, 40 grey levels) too
  EXPECT_EQ(segmenter.segment(steppedPair(100)).sherds.size(), 1u);
  EXPECT_EQ(segmenter.segment(steppedPair(40)).sherds.size(), 1u);
  EXPECT_EQ(segmenter.segment(steppedPair(0)).sherds.size(), 1u);
}

TEST(PhotoSegmenter, ClothLeakingIntoTheSherdsIsCutBackToThem) {
  // img005 darkened (gamma 1.5, bench/perception_robustness): the lamp's hotspot in the middle of the dark cloth is a little
  // lighter than the cloth's smooth estimate, weak contrast all over, and joined three sherds
  // into one blob 21 sherds large (16 found for 18); cut back, each is found once, flagged
  const cv::Mat rgb = photo("img005DSC02101.jpg");
  ASSERT_FALSE(rgb.empty());
  cv::Mat lut(1, 256, CV_8U);
  for (int i = 0; i < 256; ++i) lut.at<uint8_t>(i) = static_cast<uint8_t>(255.0 * std::pow(i / 255.0, 1.5));  // truncated, as numpy
  cv::Mat dark, bgr;
  cv::LUT(rgb, lut, dark);
  // saved as a camera would (JPEG, quality 90), as bench/perception_robustness does
  std::vector<uint8_t> jpeg;
  cv::cvtColor(dark, bgr, cv::COLOR_RGB2BGR);
  cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
  cv::cvtColor(cv::imdecode(jpeg, cv::IMREAD_COLOR), dark, cv::COLOR_BGR2RGB);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(dark);
  EXPECT_EQ(r.sherds.size(), 18u);
  int flagged = 0;
  for (const PhotoSherd& s : r.sherds) flagged += (s.flags & kLowContrast) != 0;
  EXPECT_GE(flagged, 3);
  bool said = false;
  for (const std::string& w : r.warnings) said |= w.find("cut back") != std::string::npos;
  EXPECT_TRUE(said) << "the cut-back is said";
  // the photo as taken: nothing leaks, nothing is cut back
  for (const std::string& w : PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb).warnings) {
    EXPECT_EQ(w.find("cut back"), std::string::npos) << w;
  }
}

TEST(PhotoSegmenter, CountWithinTheHandRangeOnEveryPhoto) {
  // One set of defaults for every photo. Tuned on the 8 photos without a suffix; the derived
  // ones (*_doubled_*, *_magic*, *_orig*) were only checked at the end.
  cv::FileStorage fs(kPhotos + "/photos_truth.json", cv::FileStorage::READ | cv::FileStorage::FORMAT_JSON);
  ASSERT_TRUE(fs.isOpened());
  const cv::FileNode root = fs.root();
  int in_range = 0, total = 0;
  for (const cv::FileNode& entry : root) {
    const std::string name = entry.name();
    const int lo = static_cast<int>(entry["count_range"][0]), hi = static_cast<int>(entry["count_range"][1]);
    const cv::Mat rgb = photo(name);
    ASSERT_FALSE(rgb.empty()) << name;
    const auto t0 = std::chrono::steady_clock::now();
    const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(rgb);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const int n = static_cast<int>(r.sherds.size());
    const bool ok = n >= lo && n <= hi;
    in_range += ok;
    ++total;
    std::printf("%-38s %4d  [%3d, %3d] %s %5.1f ms%s\n", name.c_str(), n, lo, hi, ok ? "  " : "!!", ms,
                r.background_trusted ? "" : "  background doubtful");
    if (kKnownFailures.count(name)) {
      if (!ok) std::printf("  known failure, not asserted: %s found %d, hand range [%d, %d]\n", name.c_str(), n, lo, hi);
      else ADD_FAILURE() << name << " is listed as a known failure but now passes: take it off the list";
      continue;
    }
    EXPECT_TRUE(ok) << name << ": " << n << " sherds, hand range [" << lo << ", " << hi << "]";
  }
  std::printf("%d of %d photos within the hand range\n", in_range, total);
}

TEST(PhotoSegmenter, NoBarNoScale) {
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(40, 40, 45));
  cv::circle(img, cv::Point(200, 150), 40, cv::Scalar(200, 150, 110), cv::FILLED);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  EXPECT_FALSE(r.bar.found);
  ASSERT_EQ(r.sherds.size(), 1u);
  EXPECT_EQ(r.sherds[0].length_mm, 0.0);
  EXPECT_TRUE(r.sherds[0].flags & kNoScale);
  EXPECT_FALSE(r.sherds[0].flags & kTouchesBorder);
  EXPECT_TRUE(r.background_trusted);
}

TEST(PhotoSegmenter, ShadowIsNotASherd) {
  // a grey cloth with a darker band of the same chromaticity (a shadow) and one sherd
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(90, 95, 100));
  cv::rectangle(img, cv::Rect(0, 100, 400, 60), cv::Scalar(45, 48, 50), cv::FILLED);
  cv::circle(img, cv::Point(300, 230), 30, cv::Scalar(200, 150, 110), cv::FILLED);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  ASSERT_EQ(r.sherds.size(), 1u);
  EXPECT_NEAR(r.sherds[0].blob.box.center.x, 300, 3);
}

TEST(PhotoSegmenter, SherdCutByTheBorderIsFlagged) {
  cv::Mat img(300, 400, CV_8UC3, cv::Scalar(40, 40, 45));
  cv::circle(img, cv::Point(10, 150), 40, cv::Scalar(200, 150, 110), cv::FILLED);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  ASSERT_EQ(r.sherds.size(), 1u);
  EXPECT_TRUE(r.sherds[0].flags & kTouchesBorder);
}

TEST(PhotoSegmenter, PhotoOfTheEmptyBackground) {
  // the empty cloth with uneven light (and a pale stain that is cloth), then one sherd on it
  cv::Mat empty(300, 400, CV_8UC3);
  for (int x = 0; x < empty.cols; ++x) empty.col(x).setTo(cv::Scalar(30 + x / 8, 32 + x / 8, 40 + x / 8));
  cv::circle(empty, cv::Point(90, 80), 25, cv::Scalar(150, 150, 150), cv::FILLED);
  cv::Mat img = empty.clone();
  cv::circle(img, cv::Point(280, 200), 35, cv::Scalar(200, 150, 110), cv::FILLED);
  const PhotoSegmenter segmenter{PhotoSegmenter::Options()};
  EXPECT_TRUE(segmenter.segment(empty, empty).sherds.empty());
  const PhotoResult r = segmenter.segment(img, empty);
  ASSERT_EQ(r.sherds.size(), 1u);
  EXPECT_NEAR(r.sherds[0].blob.box.center.x, 280, 3);
}

TEST(PhotoSegmenter, ObjectsBesideTheClothAreLeftOut) {
  // a dark sheet on a sandy floor (the floor fills the rim), buff sherds of nearly the floor's
  // colour on the sheet, and two pale things on the floor beside it
  cv::Mat img(600, 800, CV_8UC3, cv::Scalar(190, 150, 105));
  cv::Mat noise(img.size(), CV_8UC3);
  cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(4));
  const cv::Rect sheet(90, 70, 620, 460);
  cv::rectangle(img, sheet, cv::Scalar(45, 45, 50), cv::FILLED);
  // most of them near the sheet's edge, where the floor's smooth estimate reaches
  const std::vector<cv::Point> on_sheet = {{145, 115}, {400, 112}, {655, 125}, {140, 480}, {400, 300}, {650, 485}};
  for (const cv::Point& p : on_sheet) cv::ellipse(img, p, cv::Size(38, 26), 20.0, 0, 360, cv::Scalar(200, 160, 115), cv::FILLED);
  cv::circle(img, cv::Point(40, 300), 25, cv::Scalar(235, 235, 235), cv::FILLED);  // a bag beside the sheet
  cv::circle(img, cv::Point(760, 560), 20, cv::Scalar(230, 225, 220), cv::FILLED);
  img += noise;
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  EXPECT_FALSE(r.background_trusted);
  ASSERT_FALSE(r.cloth_outline.empty());
  EXPECT_GE(cv::pointPolygonTest(r.cloth_outline, cv::Point2f(400, 300), false), 0);
  ASSERT_EQ(r.sherds.size(), on_sheet.size());
  for (const PhotoSherd& s : r.sherds) EXPECT_TRUE(sheet.contains(s.blob.box.center)) << s.blob.box.center;
  bool told = false;
  for (const std::string& w : r.warnings) told = told || w.find("beside the cloth") != std::string::npos;
  EXPECT_TRUE(told);
}

TEST(PhotoSegmenter, AnUnevenlyLitClothIsNotCutToAnOutline) {
  // the cloth fills the photo, lit unevenly (a brighter half of the same chromaticity)
  cv::Mat img(400, 600, CV_8UC3, cv::Scalar(45, 45, 50));
  cv::rectangle(img, cv::Rect(300, 0, 300, 400), cv::Scalar(80, 80, 88), cv::FILLED);
  cv::circle(img, cv::Point(150, 200), 40, cv::Scalar(200, 160, 115), cv::FILLED);
  cv::circle(img, cv::Point(450, 200), 40, cv::Scalar(200, 160, 115), cv::FILLED);
  const PhotoResult r = PhotoSegmenter(PhotoSegmenter::Options()).segment(img);
  EXPECT_TRUE(r.cloth_outline.empty());
  EXPECT_EQ(r.sherds.size(), 2u);
}
