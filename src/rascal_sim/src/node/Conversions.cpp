#include "Conversions.hpp"

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cstdint>

namespace rascal_sim {
namespace conversions {

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& t, const std::string& parent,
                                            const std::string& child, const ros::Time& stamp) {
  geometry_msgs::TransformStamped m = tf2::eigenToTransform(t);
  m.header.frame_id = parent;
  m.header.stamp = stamp;
  m.child_frame_id = child;
  return m;
}

sensor_msgs::ImagePtr toImage(const cv::Mat& image, const std::string& encoding, const std::string& frame,
                              const ros::Time& stamp) {
  std_msgs::Header header;
  header.frame_id = frame;
  header.stamp = stamp;
  return cv_bridge::CvImage(header, encoding, image).toImageMsg();
}

sensor_msgs::CameraInfo toCameraInfo(const CameraModel& cam, const std::string& frame, const ros::Time& stamp) {
  sensor_msgs::CameraInfo m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.width = static_cast<uint32_t>(cam.width);
  m.height = static_cast<uint32_t>(cam.height);
  m.distortion_model = sensor_msgs::distortion_models::PLUMB_BOB;
  m.D.assign(5, 0.0);
  m.K = {cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.P = {cam.fx, 0, cam.cx, 0, 0, cam.fy, cam.cy, 0, 0, 0, 1, 0};
  return m;
}

sensor_msgs::PointCloud2 toPointCloud(const cv::Mat& depth_mm, const cv::Mat& rgb, const CameraModel& cam,
                                      const std::string& frame, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier mod(m);
  // x, y, z, rgb as float32, no padding: 16 bytes a point
  mod.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                           "z", 1, sensor_msgs::PointField::FLOAT32, "rgb", 1, sensor_msgs::PointField::FLOAT32);
  size_t n = static_cast<size_t>(cv::countNonZero(depth_mm));
  mod.resize(n);
  m.height = 1;
  m.width = static_cast<uint32_t>(n);
  m.is_dense = true;
  struct Point {
    float x, y, z;
    uint8_t b, g, r, a;  // float32 rgb field: 0x00RRGGBB, little-endian
  };
  static_assert(sizeof(Point) == 16, "point layout");
  Point* out = reinterpret_cast<Point*>(m.data.data());
  const float ifx = static_cast<float>(1.0 / cam.fx), ify = static_cast<float>(1.0 / cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  for (int v = 0; v < depth_mm.rows; ++v) {
    const uint16_t* d = depth_mm.ptr<uint16_t>(v);
    const cv::Vec3b* col = rgb.ptr<cv::Vec3b>(v);
    const float ny = (v - cy) * ify;
    for (int u = 0; u < depth_mm.cols; ++u) {
      if (d[u] == 0) continue;
      const float zz = d[u] * 0.001f;
      *out++ = {(u - cx) * ifx * zz, ny * zz, zz, col[u][2], col[u][1], col[u][0], 0};
    }
  }
  return m;
}

rascal_msgs::SherdTruth toTruth(const SherdState& s) {
  rascal_msgs::SherdTruth t;
  t.name = s.name;
  t.pose = tf2::toMsg(s.pose);
  t.mass = s.mass;
  t.thickness = s.thickness;
  t.length = s.length;
  t.width = s.width;
  for (const auto& p : s.outline) {
    geometry_msgs::Point q;
    q.x = p.x();
    q.y = p.y();
    t.outline.push_back(q);
  }
  t.color.r = static_cast<float>(s.colour.x());
  t.color.g = static_cast<float>(s.colour.y());
  t.color.b = static_cast<float>(s.colour.z());
  t.color.a = 1.0f;
  t.held = s.held;
  return t;
}

bool fromTrajectory(const trajectory_msgs::JointTrajectory& msg, std::vector<TrajectoryPoint>& points,
                    std::array<bool, kArmJoints>& mask, std::string& why) {
  const auto& names = ArmKinematics::jointNames();
  std::vector<int> index(msg.joint_names.size(), -1);
  mask.fill(false);
  for (size_t i = 0; i < msg.joint_names.size(); ++i) {
    for (int j = 0; j < kArmJoints; ++j) {
      if (msg.joint_names[i] == names[j]) {
        index[i] = j;
        mask[j] = true;
      }
    }
  }
  points.clear();
  if (msg.points.empty()) return true;  // stop
  if (std::none_of(mask.begin(), mask.end(), [](bool b) { return b; })) {
    why = "names no arm joint (waist, shoulder, elbow, forearm_roll, wrist_angle, wrist_rotate)";
    return false;
  }
  for (size_t k = 0; k < msg.points.size(); ++k) {
    const auto& p = msg.points[k];
    if (p.positions.size() != msg.joint_names.size()) {
      why = "point " + std::to_string(k) + " has " + std::to_string(p.positions.size()) + " positions for " +
            std::to_string(msg.joint_names.size()) + " joints";
      return false;
    }
    TrajectoryPoint t;
    t.has_velocities = p.velocities.size() == msg.joint_names.size();
    for (size_t i = 0; i < index.size(); ++i) {
      if (index[i] < 0) continue;
      t.positions[index[i]] = p.positions[i];
      if (t.has_velocities) t.velocities[index[i]] = p.velocities[i];
    }
    t.time_from_start = p.time_from_start.toSec();
    points.push_back(t);
  }
  return true;
}

}  // namespace conversions
}  // namespace rascal_sim
