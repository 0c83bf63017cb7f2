#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "rascal_perception/BackgroundModel.hpp"

using namespace rascal_perception;

namespace {
/// A blue mat with a darker (shadowed) half and a beige border, RGB.
cv::Mat station(double gain) {
  cv::Mat img(240, 320, CV_8UC3, cv::Scalar(140 * gain, 128 * gain, 107 * gain));
  cv::rectangle(img, cv::Rect(40, 30, 240, 180), cv::Scalar(26 * gain, 56 * gain, 140 * gain), cv::FILLED);
  cv::rectangle(img, cv::Rect(160, 30, 120, 180), cv::Scalar(13 * gain, 28 * gain, 70 * gain), cv::FILLED);
  return img;
}
}  // namespace

TEST(BackgroundModel, LearnsTheMatAndTheTableAndIgnoresBrightness) {
  BackgroundModel m;
  BackgroundOptions o;
  o.clusters = 3;
  m.learn(station(0.5), o);
  ASSERT_TRUE(m.ready());
  EXPECT_GE(m.clusters().size(), 2u);
  cv::Mat hsv, bg;
  cv::cvtColor(station(1.6), hsv, cv::COLOR_RGB2HSV_FULL);
  m.classify(hsv, cv::Mat(), bg);
  EXPECT_EQ(cv::countNonZero(bg), static_cast<int>(bg.total())) << "a brighter empty station is all background";
  EXPECT_EQ(cv::countNonZero(m.fixtureMask()), 0);
}

TEST(BackgroundModel, AnOrangeSherdIsNotBackgroundOnTheMat) {
  BackgroundModel m;
  m.learn(station(1.0), BackgroundOptions());
  cv::Mat img = station(1.0);
  cv::circle(img, cv::Point(100, 120), 20, cv::Scalar(194, 133, 102), cv::FILLED);
  cv::Mat hsv, bg;
  cv::cvtColor(img, hsv, cv::COLOR_RGB2HSV_FULL);
  m.classify(hsv, m.seenMap(), bg);
  EXPECT_EQ(bg.at<uint8_t>(120, 100), 0);
  EXPECT_EQ(bg.at<uint8_t>(120, 60), 255);
  // with the seen-map, the table's colour does not hide a beige sherd on the mat
  cv::circle(img, cv::Point(200, 120), 20, cv::Scalar(150, 130, 100), cv::FILLED);
  cv::cvtColor(img, hsv, cv::COLOR_RGB2HSV_FULL);
  m.classify(hsv, m.seenMap(), bg);
  EXPECT_EQ(bg.at<uint8_t>(120, 200), 0);
}

TEST(BackgroundModel, WhatMatchesNoClusterIsAFixture) {
  cv::Mat img = station(1.0);
  cv::rectangle(img, cv::Rect(60, 50, 30, 8), cv::Scalar(250, 250, 250), cv::FILLED);  // white bar
  BackgroundModel m;
  m.learn(img, BackgroundOptions());
  EXPECT_EQ(m.fixtureMask().at<uint8_t>(54, 75), 255);
  EXPECT_EQ(m.fixtureMask().at<uint8_t>(100, 100), 0);
}

TEST(BackgroundModel, RejectsBadInput) {
  BackgroundModel m;
  EXPECT_THROW(m.learn(cv::Mat(), BackgroundOptions()), std::invalid_argument);
  BackgroundOptions o;
  o.clusters = 9;
  EXPECT_THROW(m.learn(station(1.0), o), std::invalid_argument);
  cv::Mat hsv, bg;
  EXPECT_THROW(m.classify(hsv, cv::Mat(), bg), std::logic_error);
}

TEST(BackgroundModel, RefreshLearnsTheNewLightWithoutTheSherds) {
  BackgroundModel m;
  m.learn(station(1.0), BackgroundOptions());
  // warmer light later: the mat shifts hue; a sherd lies on it and is left out of the refresh
  cv::Mat later(240, 320, CV_8UC3, cv::Scalar(150, 128, 90));
  cv::rectangle(later, cv::Rect(40, 30, 240, 180), cv::Scalar(60, 50, 140), cv::FILLED);
  cv::Mat sherd = cv::Mat::zeros(later.size(), CV_8U);
  cv::circle(sherd, cv::Point(100, 120), 20, cv::Scalar(255), cv::FILLED);
  later.setTo(cv::Scalar(194, 133, 102), sherd);
  m.refresh(later, sherd);
  cv::Mat hsv, bg;
  cv::cvtColor(later, hsv, cv::COLOR_RGB2HSV_FULL);
  m.classify(hsv, m.seenMap(), bg);
  EXPECT_EQ(bg.at<uint8_t>(120, 200), 255);  // the mat in the new light
  EXPECT_EQ(bg.at<uint8_t>(120, 100), 0);    // the sherd
}
