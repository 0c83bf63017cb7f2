#include "rascal_workcell/Parameters.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rascal_workcell {

namespace {

std::vector<std::string> split(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

// A quoted YAML scalar ('0.5') is text, whatever it looks like; so is one the parameter-server
// bridge marks with the "!" tag.
bool isText(const YAML::Node& n) { return n.IsScalar() && n.Tag() == "!"; }

bool toNumber(const YAML::Node& n, double& out) {
  if (!n.IsScalar() || isText(n)) return false;
  const std::string& s = n.Scalar();
  if (s == "true" || s == "false" || s == "True" || s == "False") return false;
  try {
    out = n.as<double>();
  } catch (const YAML::Exception&) {
    return false;
  }
  return std::isfinite(out);
}

std::string show(const YAML::Node& n) {
  if (!n || n.IsNull()) return "nothing";
  if (n.IsScalar()) {
    double d = 0.0;
    if (!toNumber(n, d)) return "'" + n.Scalar() + "'";
    std::ostringstream ss;
    ss << d;
    return ss.str();
  }
  YAML::Emitter out;
  out << YAML::Flow << n;
  return out.c_str();
}

}  // namespace

Parameters::Parameters(YAML::Node root, std::string reader, const ParameterSchema& schema)
    : root_(std::move(root)), reader_(std::move(reader)), schema_(schema) {
  if (!root_.IsMap()) throw ParameterError("configuration: expected a mapping of sections");
}

Parameters Parameters::fromFile(const std::string& path, const std::string& reader,
                                const ParameterSchema& schema) {
  try {
    return Parameters(YAML::LoadFile(path), reader, schema);
  } catch (const YAML::BadFile&) {
    throw ParameterError(path + ": cannot be read; pass the path of config/rascal.yaml");
  } catch (const YAML::Exception& e) {
    throw ParameterError(path + ": not valid YAML: " + e.what());
  }
}

const ParameterSpec& Parameters::spec(const std::string& key, const char* method) const {
  const ParameterSpec* s = schema_.find(key);
  if (!s) {
    throw std::logic_error(std::string("Parameters::") + method + ": '" + key +
                           "' is not in schema/parameters.yaml");
  }
  if (!s->readBy(reader_)) {
    throw std::logic_error(std::string("Parameters::") + method + ": '" + key +
                           "' is not declared for reader '" + reader_ + "' in schema/parameters.yaml");
  }
  read_.insert(s->key);
  return *s;
}

YAML::Node Parameters::lookup(const std::string& key) const {
  YAML::Node cur;
  cur.reset(root_);
  for (const std::string& part : split(key)) {
    if (!cur.IsMap() || !cur[part]) return YAML::Node(YAML::NodeType::Undefined);
    YAML::Node next = cur[part];
    cur.reset(next);  // rebind; `cur = next` would overwrite the tree
  }
  return cur;
}

bool Parameters::has(const std::string& key) const {
  // Looking whether an optional key is there is reading it: a node that asks and finds none
  // (a station without calibration markers) has not ignored the key.
  const ParameterSpec* s = schema_.find(key);
  if (s && s->readBy(reader_)) read_.insert(s->key);
  const YAML::Node n = lookup(key);
  return n.IsDefined() && !n.IsNull();
}

YAML::Node Parameters::valueOrDefault(const std::string& key, const ParameterSpec& s) const {
  YAML::Node n = lookup(key);
  if (n.IsDefined() && !n.IsNull()) return n;
  if (s.required) {
    throw ParameterError(key + ": missing; add it (see the shipped config/rascal.yaml)");
  }
  return s.default_value;
}

void Parameters::fail(const std::string& key, const ParameterSpec& s, const YAML::Node& got) const {
  throw ParameterError(key + ": expected " + s.expectation() + ", got " + show(got));
}

double Parameters::bound(const std::string& key, const ParameterSpec& s, bool upper) const {
  const std::string& other = upper ? s.max_key : s.min_key;
  if (other.empty()) {
    const auto& b = upper ? s.max : s.min;
    return b ? *b : (upper ? INFINITY : -INFINITY);
  }
  // A bound named by another key is that key's value (its own checks apply; no reader check:
  // the bound belongs to this key's rule).
  const ParameterSpec* o = schema_.find(other);
  if (!o) throw std::logic_error("schema: " + key + " is bounded by unknown key " + other);
  double v = 0.0;
  const YAML::Node n = valueOrDefault(other, *o);
  if (!toNumber(n, v)) fail(other, *o, n);
  (void)key;
  return v;
}

double Parameters::number(const std::string& key) const {
  const ParameterSpec& s = spec(key, "number");
  const YAML::Node n = valueOrDefault(key, s);
  double v = 0.0;
  if (!toNumber(n, v)) fail(key, s, n);
  if (s.type == "integer" && std::floor(v) != v) fail(key, s, n);
  const double lo = bound(key, s, false), hi = bound(key, s, true);
  if (v < lo || v > hi || (s.exclusive_min && v == lo)) {
    ParameterSpec shown = s;  // name the values of key-named bounds in the message
    if (!s.min_key.empty()) shown.min_key = s.min_key + " = " + show(YAML::Node(lo));
    if (!s.max_key.empty()) shown.max_key = s.max_key + " = " + show(YAML::Node(hi));
    fail(key, shown, n);
  }
  return v;
}

int Parameters::integer(const std::string& key) const {
  const ParameterSpec& s = spec(key, "integer");
  if (s.type != "integer") throw std::logic_error("Parameters::integer: " + key + " is a " + s.type);
  return static_cast<int>(number(key));
}

bool Parameters::flag(const std::string& key) const {
  const ParameterSpec& s = spec(key, "flag");
  const YAML::Node n = valueOrDefault(key, s);
  if (!n.IsScalar() || isText(n)) fail(key, s, n);
  const std::string& v = n.Scalar();
  if (v == "true" || v == "True") return true;
  if (v == "false" || v == "False") return false;
  fail(key, s, n);
}

std::string Parameters::text(const std::string& key) const {
  const ParameterSpec& s = spec(key, "text");
  const YAML::Node n = valueOrDefault(key, s);
  if (!n.IsScalar()) fail(key, s, n);
  const std::string v = n.Scalar();
  if (s.type == "enum") {
    if (std::find(s.choices.begin(), s.choices.end(), v) == s.choices.end()) fail(key, s, n);
    return v;
  }
  const bool blank = v.find_first_not_of(" \t") == std::string::npos;
  const bool control = std::any_of(v.begin(), v.end(), [](char c) { return static_cast<unsigned char>(c) < 32; });
  if (blank || control || (s.max_length > 0 && static_cast<int>(v.size()) > s.max_length)) fail(key, s, n);
  return v;
}

std::vector<double> Parameters::vector(const std::string& key) const {
  const ParameterSpec& s = spec(key, "vector");
  const YAML::Node n = valueOrDefault(key, s);
  if (!n.IsSequence() || static_cast<int>(n.size()) != s.length) fail(key, s, n);
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    const double lo = i < s.min_each.size() ? s.min_each[i] : bound(key, s, false);
    const double hi = i < s.max_each.size() ? s.max_each[i] : bound(key, s, true);
    if (!toNumber(n[i], v) || v < lo || v > hi) fail(key, s, n);
    out.push_back(v);
  }
  return out;
}

std::vector<std::vector<double>> Parameters::vectors(const std::string& key) const {
  const ParameterSpec& s = spec(key, "vectors");
  const YAML::Node n = valueOrDefault(key, s);
  if (!n.IsSequence() || static_cast<int>(n.size()) != s.length) fail(key, s, n);
  std::vector<std::vector<double>> out;
  for (const auto& inner : n) {
    if (!inner.IsSequence() || static_cast<int>(inner.size()) != s.inner_length) fail(key, s, n);
    std::vector<double> v;
    for (const auto& e : inner) {
      double d = 0.0;
      if (!toNumber(e, d) || d < bound(key, s, false) || d > bound(key, s, true)) fail(key, s, n);
      v.push_back(d);
    }
    out.push_back(v);
  }
  return out;
}

Eigen::Vector2d Parameters::xy(const std::string& key) const {
  const auto v = vector(key);
  if (v.size() != 2) throw std::logic_error("Parameters::xy: " + key + " is not a 2-vector");
  return {v[0], v[1]};
}

Eigen::Vector3d Parameters::vector3(const std::string& key) const {
  const auto v = vector(key);
  if (v.size() != 3) throw std::logic_error("Parameters::vector3: " + key + " is not a 3-vector");
  return {v[0], v[1], v[2]};
}

std::vector<std::string> Parameters::names(const std::string& key) const {
  const ParameterSpec& s = spec(key, "names");
  const YAML::Node n = valueOrDefault(key, s);
  if (!n.IsMap() || n.size() == 0) fail(key, s, n);
  std::vector<std::string> out;
  for (const auto& e : n) out.push_back(e.first.as<std::string>());
  for (const std::string& name : s.required_names) {
    if (std::find(out.begin(), out.end(), name) == out.end()) {
      throw ParameterError(key + "." + name + ": missing; add it (see the shipped config/rascal.yaml)");
    }
  }
  return out;
}

std::vector<std::string> Parameters::unread() const {
  std::vector<std::string> out;
  for (const ParameterSpec& s : schema_.specs()) {
    if (s.readBy(reader_) && !read_.count(s.key)) out.push_back(s.key);
  }
  return out;
}

void Parameters::checkAllRead() const {
  const auto missing = unread();
  if (missing.empty()) return;
  std::string list;
  for (const auto& k : missing) list += (list.empty() ? "" : ", ") + k;
  throw std::logic_error("reader '" + reader_ + "' never read " + list +
                         " although schema/parameters.yaml lists it as a reader");
}

}  // namespace rascal_workcell
