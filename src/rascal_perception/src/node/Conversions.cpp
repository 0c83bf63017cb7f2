#include "Conversions.hpp"

#include <cv_bridge/cv_bridge.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace rascal_perception {
namespace conversions {

namespace enc = sensor_msgs::image_encodings;

cv::Mat colourImage(const sensor_msgs::Image& msg) {
  if (msg.encoding != enc::RGB8 && msg.encoding != enc::BGR8) {
    throw std::invalid_argument("colour encoding '" + msg.encoding + "' (need rgb8 or bgr8)");
  }
  try {
    return cv_bridge::toCvCopy(msg, enc::RGB8)->image;  // bgr8 is converted
  } catch (const cv_bridge::Exception& e) {
    throw std::invalid_argument("malformed " + msg.encoding + " image: " + e.what());
  }
}

cv::Mat depthImage(const sensor_msgs::Image& msg) {
  const bool mm = msg.encoding == enc::TYPE_16UC1 || msg.encoding == enc::MONO16;
  if (!mm && msg.encoding != enc::TYPE_32FC1) {
    throw std::invalid_argument("depth encoding '" + msg.encoding + "' (need 16UC1 mm or 32FC1 m)");
  }
  cv_bridge::CvImageConstPtr in;
  try {
    in = cv_bridge::toCvShare(msg, nullptr);  // the message's pixels, size-checked, not copied
  } catch (const cv_bridge::Exception& e) {
    throw std::invalid_argument("malformed " + msg.encoding + " image: " + e.what());
  }
  cv::Mat out;
  if (mm) {
    in->image.copyTo(out);
  } else {
    in->image.convertTo(out, CV_16UC1, 1000.0);  // metres -> millimetres, rounded, saturated
  }
  return out;
}

sensor_msgs::Image toImage(const cv::Mat& rgb, const std_msgs::Header& header) {
  sensor_msgs::Image m;
  cv_bridge::CvImage(header, enc::RGB8, rgb).toImageMsg(m);
  return m;
}

CameraIntrinsics intrinsics(const sensor_msgs::CameraInfo& info) {
  CameraIntrinsics k;
  k.width = static_cast<int>(info.width);
  k.height = static_cast<int>(info.height);
  k.fx = info.K[0];
  k.fy = info.K[4];
  k.cx = info.K[2];
  k.cy = info.K[5];
  if (k.fx <= 0 || k.fy <= 0) throw std::invalid_argument("camera_info has no focal length (K[0], K[4])");
  return k;
}

rascal_msgs::Sherd toSherd(const SherdDetection& d, const std_msgs::Header& header, uint32_t id) {
  rascal_msgs::Sherd s;
  s.header = header;
  s.id = id;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = d.centre;
  pose.linear() = Eigen::AngleAxisd(d.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.pose = tf2::toMsg(pose);
  s.length = d.length;
  s.width = d.width;
  s.height = d.height;
  s.support = d.support;
  s.thickness = d.thickness;
  s.covered = d.covered;
  s.grasp_clear = d.grasp_clear;
  s.vessel_diameter = d.diameter;
  s.vessel_diameter_sigma = d.diameter_sigma;
  s.area = d.area;
  s.color.r = static_cast<float>(d.colour.x());
  s.color.g = static_cast<float>(d.colour.y());
  s.color.b = static_cast<float>(d.colour.z());
  s.color.a = 1.0f;
  s.grasp_pose = tf2::toMsg(d.grasp);
  s.grasp_width = d.grasp_width;
  s.score = d.score;
  for (int i = 0; i < 5; ++i) s.image_box[i] = d.image_box[i];
  for (const Eigen::Vector3d& p : d.outline) s.outline.push_back(tf2::toMsg(p));
  return s;
}

rascal_msgs::Leftover toLeftover(const Leftover& l) {
  rascal_msgs::Leftover m;
  m.position = tf2::toMsg(l.position);
  m.length = l.length;
  m.width = l.width;
  m.yaw = l.yaw;
  m.height = l.height;
  m.on_edge = l.on_edge;
  m.cut_by_border = l.cut_by_border;
  m.why = l.why;
  return m;
}

namespace {
/// An ADD marker with an identity orientation (rviz drops markers with a zero quaternion).
visualization_msgs::Marker newMarker(const std_msgs::Header& header, const char* ns, size_t id, int type) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = static_cast<int>(id);
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  return m;
}

std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r, c.g = g, c.b = b, c.a = a;
  return c;
}
}  // namespace

visualization_msgs::MarkerArray markers(const std::vector<SherdDetection>& sherds, const std_msgs::Header& header,
                                        const std::vector<Leftover>& leftovers) {
  visualization_msgs::MarkerArray a;
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  a.markers.push_back(clear);
  for (size_t i = 0; i < sherds.size(); ++i) {
    const SherdDetection& d = sherds[i];
    visualization_msgs::Marker box = newMarker(header, "sherds", i, visualization_msgs::Marker::CUBE);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    // from what it rests on (the table, or the sherd under it in a heap) to its top
    const double h = std::max(d.height - d.support, 0.002);
    pose.translation() = Eigen::Vector3d(d.centre.x(), d.centre.y(), d.surface + d.support + 0.5 * h);
    pose.linear() = Eigen::AngleAxisd(d.yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    box.pose = tf2::toMsg(pose);
    box.scale.x = d.length;
    box.scale.y = d.width;
    box.scale.z = h;
    // red: the best scored; green: free to pick; orange: the fingers would land on a
    // neighbour; grey: lies under another sherd (picked later)
    const bool under = d.covered > 0.05;
    box.color.r = under ? 0.6f : (i == 0 || !d.grasp_clear) ? 1.0f : 0.2f;
    box.color.g = under ? 0.6f : i == 0 ? 0.3f : d.grasp_clear ? 0.9f : 0.6f;
    box.color.b = under ? 0.6f : 0.2f;
    box.color.a = under ? 0.3f : 0.5f;
    a.markers.push_back(box);

    visualization_msgs::Marker arrow = box;
    arrow.ns = "grasps";
    arrow.type = visualization_msgs::Marker::ARROW;
    arrow.pose = geometry_msgs::Pose();
    arrow.pose.orientation.w = 1.0;
    const geometry_msgs::Point to = tf2::toMsg(Eigen::Vector3d(d.grasp.translation()));
    geometry_msgs::Point from = to;
    from.z += 0.06;
    arrow.points = {from, to};
    arrow.scale.x = 0.004;
    arrow.scale.y = 0.008;
    arrow.scale.z = 0.01;
    arrow.color = rgba(1.0f, 0.0f, 1.0f, 1.0f);
    a.markers.push_back(arrow);

    visualization_msgs::Marker fingers = arrow;  // the closing direction, across the minor axis
    fingers.ns = "fingers";
    fingers.type = visualization_msgs::Marker::LINE_LIST;
    const Eigen::Vector3d across = d.grasp.linear().col(1) * (0.5 * d.grasp_width);
    geometry_msgs::Point l = to, r = to;
    l.x += across.x(), l.y += across.y();
    r.x -= across.x(), r.y -= across.y();
    fingers.points = {l, r};
    fingers.scale.x = 0.002;
    a.markers.push_back(fingers);

    visualization_msgs::Marker text = box;
    text.ns = "labels";
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.pose.position.z = d.centre.z() + 0.02;
    text.pose.orientation = geometry_msgs::Quaternion();
    text.pose.orientation.w = 1.0;
    text.scale.z = 0.012;
    text.color.r = text.color.g = text.color.b = text.color.a = 1.0f;
    char buf[128];
    std::snprintf(buf, sizeof(buf), "#%zu %.0fx%.0f mm, wall %.1f mm%s%s", i, d.length * 1e3, d.width * 1e3,
                  d.thickness * 1e3, under ? ", under another" : "", d.grasp_clear ? "" : ", fingers blocked");
    text.text = buf;
    a.markers.push_back(text);
  }
  for (size_t i = 0; i < leftovers.size(); ++i) {
    const Leftover& l = leftovers[i];
    visualization_msgs::Marker disc = newMarker(header, "leftovers", i, visualization_msgs::Marker::CYLINDER);
    disc.pose.position = tf2::toMsg(l.position);
    disc.scale.x = disc.scale.y = std::max(l.length, 0.005);
    disc.scale.z = 0.002;
    disc.color = rgba(1.0f, 0.85f, 0.0f, 0.8f);
    a.markers.push_back(disc);
    visualization_msgs::Marker text = disc;
    text.ns = "leftover_labels";
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.pose.position.z += 0.02;
    text.scale.z = 0.012;
    text.color.r = text.color.g = text.color.b = text.color.a = 1.0f;
    text.text = "not taken: " + l.why;
    a.markers.push_back(text);
  }
  return a;
}

}  // namespace conversions
}  // namespace rascal_perception
