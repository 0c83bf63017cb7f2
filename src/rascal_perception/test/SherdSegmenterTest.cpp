#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "rascal_perception/SherdSegmenter.hpp"

using namespace rascal_perception;

TEST(SherdSegmenter, SplitsTwoTouchingDiscs) {
  cv::Mat m = cv::Mat::zeros(200, 300, CV_8U);
  cv::circle(m, cv::Point(100, 100), 40, cv::Scalar(255), cv::FILLED);
  cv::circle(m, cv::Point(175, 105), 38, cv::Scalar(255), cv::FILLED);
  SegmentationOptions o;
  o.min_side_px = 20;
  SegmentationStats st;
  const auto blobs = SherdSegmenter().blobs(m, o, &st);
  ASSERT_EQ(blobs.size(), 2u);
  EXPECT_EQ(st.splits, 1);
  EXPECT_NEAR(blobs[0].box.center.x + blobs[1].box.center.x, 275, 10);
}

TEST(SherdSegmenter, KeepsAnElongatedIrregularSherdWhole) {
  cv::Mat m = cv::Mat::zeros(200, 300, CV_8U);
  std::vector<cv::Point> poly{{60, 80}, {150, 60}, {240, 90}, {230, 130}, {150, 140}, {70, 125}};
  cv::fillPoly(m, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(255));
  SegmentationOptions o;
  o.min_side_px = 20;
  EXPECT_EQ(SherdSegmenter().blobs(m, o).size(), 1u);
}

TEST(SherdSegmenter, RejectsBlobsCutByTheBorderAndNoise) {
  cv::Mat m = cv::Mat::zeros(200, 300, CV_8U);
  cv::circle(m, cv::Point(10, 100), 30, cv::Scalar(255), cv::FILLED);   // cut by the left edge
  cv::circle(m, cv::Point(150, 100), 30, cv::Scalar(255), cv::FILLED);  // whole
  cv::rectangle(m, cv::Rect(250, 20, 3, 3), cv::Scalar(255), cv::FILLED);  // noise
  SegmentationOptions o;
  o.min_side_px = 20;
  SegmentationStats st;
  const auto blobs = SherdSegmenter().blobs(m, o, &st);
  ASSERT_EQ(blobs.size(), 1u);
  EXPECT_EQ(st.rejected_border, 1);
  EXPECT_NEAR(blobs[0].box.center.x, 150, 1.0);
}

TEST(SherdSegmenter, RejectsBlobsLargerThanOneSherd) {
  cv::Mat m = cv::Mat::zeros(200, 300, CV_8U);
  cv::rectangle(m, cv::Rect(20, 20, 200, 60), cv::Scalar(255), cv::FILLED);
  SegmentationOptions o;
  o.min_side_px = 20;
  o.max_side_px = 150;
  SegmentationStats st;
  EXPECT_TRUE(SherdSegmenter().blobs(m, o, &st).empty());
  EXPECT_EQ(st.rejected_size, 1);
}
