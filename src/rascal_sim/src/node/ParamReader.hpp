#pragma once
// Reads and checks parameters; every failure is a ParamError whose message names the key.
#include <ros/node_handle.h>

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

namespace rascal_sim {

class ParamError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}
  double number(const std::string& key, double lo, double hi) const;               // required
  double number(const std::string& key, double def, double lo, double hi) const;   // optional
  bool flag(const std::string& key, bool def) const;
  std::string text(const std::string& key) const;                                  // required
  std::string text(const std::string& key, const std::string& def) const;
  /// A list of n numbers, each in [lo, hi]; `def` is used when the key is absent (empty = required).
  std::vector<double> list(const std::string& key, size_t n, double lo, double hi,
                           const std::vector<double>& def = {}) const;
  Eigen::Vector2d vec2(const std::string& key) const;
  Eigen::Vector3d colour(const std::string& key) const;
  /// A list of n sRGB colours [[r, g, b], ...] in [0, 1].
  std::vector<Eigen::Vector3d> colours(const std::string& key, size_t n) const;

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& why) const;
  ros::NodeHandle nh_;
};

}  // namespace rascal_sim
