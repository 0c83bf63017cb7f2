// The node's message conversions (cv_bridge, tf2_eigen and the hand-written rest), without a
// master: depth units, colour order, malformed images, poses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "../src/node/Conversions.hpp"

using namespace rascal_perception;

namespace {
template <typename T>
sensor_msgs::Image image(const std::string& encoding, int width, int height, const std::vector<T>& pixels,
                         int channels = 1) {
  sensor_msgs::Image m;
  m.encoding = encoding;
  m.width = width;
  m.height = height;
  m.step = static_cast<uint32_t>(width * channels * sizeof(T));
  m.data.resize(pixels.size() * sizeof(T));
  std::memcpy(m.data.data(), pixels.data(), m.data.size());
  return m;
}
}  // namespace

TEST(Conversions, DepthIn16UC1IsMillimetresAlready) {
  const cv::Mat d = conversions::depthImage(image<uint16_t>("16UC1", 2, 1, {250, 0}));
  ASSERT_EQ(d.type(), CV_16UC1);
  EXPECT_EQ(d.at<uint16_t>(0, 0), 250);
  EXPECT_EQ(d.at<uint16_t>(0, 1), 0);
}

TEST(Conversions, DepthIn32FC1MetresBecomesMillimetres) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat d = conversions::depthImage(image<float>("32FC1", 4, 1, {0.2504f, nan, -1.0f, 70.0f}));
  ASSERT_EQ(d.type(), CV_16UC1);
  EXPECT_EQ(d.at<uint16_t>(0, 0), 250);    // rounded to the millimetre
  EXPECT_EQ(d.at<uint16_t>(0, 1), 0);      // no depth
  EXPECT_EQ(d.at<uint16_t>(0, 2), 0);      // no depth
  EXPECT_EQ(d.at<uint16_t>(0, 3), 65535);  // saturated (beyond any depth_max)
}

TEST(Conversions, ColourComesOutRgbWhicheverOrderCameIn) {
  const std::vector<uint8_t> px{10, 20, 30};
  const cv::Mat rgb = conversions::colourImage(image<uint8_t>("rgb8", 1, 1, px, 3));
  const cv::Mat bgr = conversions::colourImage(image<uint8_t>("bgr8", 1, 1, px, 3));
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
  // the annotated image goes back out as rgb8
  const sensor_msgs::Image out = conversions::toImage(rgb, std_msgs::Header());
  EXPECT_EQ(out.encoding, "rgb8");
  EXPECT_EQ(out.step, 3u);
  EXPECT_EQ(out.data, px);
}

TEST(Conversions, WrongEncodingsAndShortImagesAreRefused) {
  EXPECT_THROW(conversions::colourImage(image<uint8_t>("mono8", 1, 1, {1})), std::invalid_argument);
  EXPECT_THROW(conversions::depthImage(image<uint8_t>("rgb8", 1, 1, {1, 2, 3}, 3)), std::invalid_argument);
  sensor_msgs::Image short_depth = image<uint16_t>("16UC1", 2, 2, {1, 2});  // half the rows missing
  EXPECT_THROW(conversions::depthImage(short_depth), std::invalid_argument);
  sensor_msgs::Image short_colour = image<uint8_t>("rgb8", 2, 1, {1, 2, 3}, 3);
  EXPECT_THROW(conversions::colourImage(short_colour), std::invalid_argument);
}

TEST(Conversions, SherdPoseCarriesTheYawAboutZ) {
  SherdDetection d;
  d.centre = Eigen::Vector3d(0.2, 0.25, 0.01);
  d.yaw = 0.7;
  d.grasp.translation() = Eigen::Vector3d(0.2, 0.25, 0.015);
  d.outline = {Eigen::Vector3d(0.19, 0.24, 0.0), Eigen::Vector3d(0.21, 0.26, 0.0)};
  d.height = 0.015;
  d.support = 0.009;  // it lies on another sherd: its own height is height - support
  const rascal_msgs::Sherd s = conversions::toSherd(d, std_msgs::Header(), 3);
  EXPECT_EQ(s.id, 3u);
  EXPECT_DOUBLE_EQ(s.height, 0.015);
  EXPECT_DOUBLE_EQ(s.support, 0.009);
  EXPECT_DOUBLE_EQ(s.pose.position.x, 0.2);
  EXPECT_NEAR(2.0 * std::atan2(s.pose.orientation.z, s.pose.orientation.w), 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(s.grasp_pose.position.z, 0.015);
  ASSERT_EQ(s.outline.size(), 2u);
  EXPECT_DOUBLE_EQ(s.outline[1].y, 0.26);
  const visualization_msgs::MarkerArray m = conversions::markers({d}, std_msgs::Header());
  ASSERT_EQ(m.markers.size(), 5u);  // DELETEALL, box, arrow, fingers, label
  EXPECT_EQ(m.markers[0].action, visualization_msgs::Marker::DELETEALL);
}

TEST(Conversions, LeftoversAreDiscsSayingWhyTheyAreNotTaken) {
  Leftover l;
  l.position = Eigen::Vector3d(0.15, 0.3, 0.002);
  l.length = 0.012;
  l.width = 0.009;
  l.yaw = -0.4;
  l.height = 0.02;
  l.on_edge = true;
  l.why = "narrower than perception.min_sherd_size";
  const rascal_msgs::Leftover msg = conversions::toLeftover(l);
  EXPECT_DOUBLE_EQ(msg.position.y, 0.3);
  EXPECT_DOUBLE_EQ(msg.width, 0.009);
  EXPECT_DOUBLE_EQ(msg.yaw, -0.4);
  EXPECT_DOUBLE_EQ(msg.height, 0.02);
  EXPECT_TRUE(msg.on_edge);
  EXPECT_EQ(msg.why, l.why);
  const visualization_msgs::MarkerArray m = conversions::markers({}, std_msgs::Header(), {l});
  ASSERT_EQ(m.markers.size(), 3u);  // DELETEALL, disc, label
  EXPECT_EQ(m.markers[1].ns, "leftovers");
  EXPECT_DOUBLE_EQ(m.markers[1].scale.x, 0.012);
  EXPECT_NE(m.markers[2].text.find("min_sherd_size"), std::string::npos);
}
