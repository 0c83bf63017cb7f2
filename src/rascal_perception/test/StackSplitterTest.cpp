// StackSplitter on synthetic height maps: what lies on what, within one blob and across blobs.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "rascal_perception/SherdSegmenter.hpp"
#include "rascal_perception/StackSplitter.hpp"

using namespace rascal_perception;

namespace {

constexpr int kSize = 120;

Blob blobOf(const cv::Mat& mask) {
  const cv::Rect box = cv::boundingRect(mask);
  return SherdSegmenter::blobOf(mask(box), box.tl());
}

cv::Mat rect(const cv::Rect& r) {
  cv::Mat m = cv::Mat::zeros(kSize, kSize, CV_8U);
  m(r).setTo(255);
  return m;
}

StackOptions options() {
  StackOptions o;
  o.min_area_px = 400;
  return o;
}

}  // namespace

TEST(StackSplitter, AFlatSherdIsOnePartNothingLiesOn) {
  cv::Mat h(kSize, kSize, CV_32F, cv::Scalar(0.0f));
  h(cv::Rect(20, 20, 60, 40)).setTo(0.006f);
  const std::vector<StackPart> parts = StackSplitter().split(blobOf(rect({20, 20, 60, 40})), h, options());
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_EQ(parts[0].covered, 0.0);
  EXPECT_EQ(parts[0].support, 0.0);
}

TEST(StackSplitter, ANeighboursEdgeSeenOnASherdCoversIt) {
  // a 6 mm sherd with a strip 8 px wide of another's end on it (at 14 mm): too small to be a
  // part, the rest of that neighbour cut apart before; the sherd's outline stays whole
  cv::Mat h(kSize, kSize, CV_32F, cv::Scalar(0.0f));
  h(cv::Rect(20, 20, 60, 40)).setTo(0.006f);
  h(cv::Rect(72, 20, 8, 40)).setTo(0.014f);
  const Blob blob = blobOf(rect({20, 20, 60, 40}));
  const std::vector<StackPart> parts = StackSplitter().split(blob, h, options());
  ASSERT_EQ(parts.size(), 1u);
  EXPECT_GT(parts[0].covered, 0.05);
  EXPECT_EQ(parts[0].blob.pixels, blob.pixels);
  // the same strip lower than the sherd (its rim mixed with the table) covers nothing
  h(cv::Rect(72, 20, 8, 40)).setTo(0.001f);
  const std::vector<StackPart> rim = StackSplitter().split(blob, h, options());
  ASSERT_EQ(rim.size(), 1u);
  EXPECT_EQ(rim[0].covered, 0.0);
  EXPECT_EQ(rim[0].support, 0.0);
}

TEST(StackSplitter, ASherdLyingOnAnotherOfItsBlobIsCutOutAndRestsOnIt) {
  cv::Mat h(kSize, kSize, CV_32F, cv::Scalar(0.0f));
  h(cv::Rect(10, 20, 60, 40)).setTo(0.006f);
  h(cv::Rect(50, 20, 60, 40)).setTo(0.013f);  // on the first one's right half, and beyond it
  const std::vector<StackPart> parts = StackSplitter().split(blobOf(rect({10, 20, 100, 40})), h, options());
  ASSERT_EQ(parts.size(), 2u);
  const StackPart& low = parts[0].blob.box.center.x < parts[1].blob.box.center.x ? parts[0] : parts[1];
  const StackPart& top = &low == &parts[0] ? parts[1] : parts[0];
  EXPECT_GT(low.covered, 0.05);
  EXPECT_EQ(top.covered, 0.0);
  EXPECT_NEAR(top.support, 0.006, 1e-6);
}

TEST(StackSplitter, ANeighbourOfAnotherBlobCoversOnlyWhereItLiesOnTheSherd) {
  // two blobs side by side (cut apart at a neck): the right one 8 mm higher along the shared
  // edge. With a 7 mm wall its underside is near the left one's top (6 mm): it lies on it.
  // With a 13 mm wall it stands on the table beside it.
  cv::Mat h(kSize, kSize, CV_32F, cv::Scalar(0.0f));
  const cv::Mat left = rect({10, 20, 50, 40}), right = rect({60, 20, 50, 40});
  h.setTo(0.006f, left);
  h.setTo(0.014f, right);
  const Blob a = blobOf(left), b = blobOf(right);
  const std::vector<const Blob*> parts = {&a, &b};
  const std::vector<double> on = StackSplitter::coveredAcross(parts, {0, 1}, {0.006, 0.007}, h, options());
  EXPECT_GT(on[0], 0.05);
  EXPECT_EQ(on[1], 0.0);
  const std::vector<double> beside = StackSplitter::coveredAcross(parts, {0, 1}, {0.006, 0.013}, h, options());
  EXPECT_EQ(beside[0], 0.0);
  // an unmeasured wall is not taken to lie on anything; parts of one blob are split()'s
  EXPECT_EQ(StackSplitter::coveredAcross(parts, {0, 1}, {0.006, 0.0}, h, options())[0], 0.0);
  EXPECT_EQ(StackSplitter::coveredAcross(parts, {0, 0}, {0.006, 0.007}, h, options())[0], 0.0);
  EXPECT_EQ(StackSplitter::coveredAcross(parts, {0, 1}, {0.006, 0.007}, cv::Mat(), options())[0], 0.0);
}
