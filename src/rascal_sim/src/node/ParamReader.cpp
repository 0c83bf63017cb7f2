#include "ParamReader.hpp"

#include <sstream>

namespace rascal_sim {

namespace {
bool asDouble(const XmlRpc::XmlRpcValue& v, double& out) {
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) {
    out = static_cast<double>(const_cast<XmlRpc::XmlRpcValue&>(v));
    return true;
  }
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) {
    out = static_cast<int>(const_cast<XmlRpc::XmlRpcValue&>(v));
    return true;
  }
  return false;
}
}  // namespace

void ParamReader::fail(const std::string& key, const std::string& why) const {
  throw ParamError("parameter " + nh_.resolveName(key) + ": " + why);
}

double ParamReader::number(const std::string& key, double lo, double hi) const {
  if (!nh_.hasParam(key)) fail(key, "missing (required)");
  return number(key, 0.0, lo, hi);
}

double ParamReader::number(const std::string& key, double def, double lo, double hi) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return def;
  double d = 0.0;
  if (!asDouble(v, d)) fail(key, "expected a number");
  if (d < lo || d > hi) {
    std::ostringstream ss;
    ss << "value " << d << " outside [" << lo << ", " << hi << "]";
    fail(key, ss.str());
  }
  return d;
}

bool ParamReader::flag(const std::string& key, bool def) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return def;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) fail(key, "expected true or false");
  return static_cast<bool>(v);
}

std::string ParamReader::text(const std::string& key) const {
  if (!nh_.hasParam(key)) fail(key, "missing (required)");
  return text(key, "");
}

std::string ParamReader::text(const std::string& key, const std::string& def) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return def;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString) fail(key, "expected a string");
  return static_cast<std::string>(v);
}

std::vector<double> ParamReader::list(const std::string& key, size_t n, double lo, double hi,
                                      const std::vector<double>& def) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) {
    if (def.empty()) fail(key, "missing (required)");
    return def;
  }
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || static_cast<size_t>(v.size()) != n) {
    fail(key, "expected a list of " + std::to_string(n) + " numbers");
  }
  std::vector<double> out;
  for (int i = 0; i < v.size(); ++i) {
    double d = 0.0;
    if (!asDouble(v[i], d)) fail(key, "expected numbers in the list");
    if (d < lo || d > hi) {
      std::ostringstream ss;
      ss << "element " << i << " = " << d << " outside [" << lo << ", " << hi << "]";
      fail(key, ss.str());
    }
    out.push_back(d);
  }
  return out;
}

Eigen::Vector2d ParamReader::vec2(const std::string& key) const {
  const auto v = list(key, 2, -2.0, 2.0);
  return {v[0], v[1]};
}

Eigen::Vector3d ParamReader::colour(const std::string& key) const {
  const auto v = list(key, 3, 0.0, 1.0);
  return {v[0], v[1], v[2]};
}

std::vector<Eigen::Vector3d> ParamReader::colours(const std::string& key, size_t n) const {
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) fail(key, "missing (required)");
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || static_cast<size_t>(v.size()) != n) {
    fail(key, "expected a list of " + std::to_string(n) + " colours [r, g, b]");
  }
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < v.size(); ++i) {
    if (v[i].getType() != XmlRpc::XmlRpcValue::TypeArray || v[i].size() != 3) {
      fail(key, "colour " + std::to_string(i) + " is not [r, g, b]");
    }
    Eigen::Vector3d c;
    for (int j = 0; j < 3; ++j) {
      if (!asDouble(v[i][j], c[j]) || c[j] < 0.0 || c[j] > 1.0) {
        fail(key, "colour " + std::to_string(i) + " needs numbers in [0, 1]");
      }
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace rascal_sim
