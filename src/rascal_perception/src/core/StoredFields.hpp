#pragma once
// Reading numbers back from a cv::FileStorage node: FileNode's own conversion turns a missing
// or non-numeric field into 0 without a word, and a kept background read so would be wrong
// without a sign (a focal length of 0, a hue of 0). Private to the core library.
#include <opencv2/core/persistence.hpp>
#include <stdexcept>
#include <string>

namespace rascal_perception {

/// node[key] as a number; throws std::invalid_argument("<where>: <key> missing") when the field
/// is absent or not a number.
inline double storedNumber(const cv::FileNode& node, const char* key, const std::string& where) {
  const cv::FileNode n = node[key];
  if (n.empty() || !(n.isReal() || n.isInt())) throw std::invalid_argument(where + ": " + key + " missing");
  return static_cast<double>(n);
}

inline int storedInt(const cv::FileNode& node, const char* key, const std::string& where) {
  const cv::FileNode n = node[key];
  if (n.empty() || !n.isInt()) throw std::invalid_argument(where + ": " + key + " missing");
  return static_cast<int>(n);
}

}  // namespace rascal_perception
