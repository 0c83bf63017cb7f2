#pragma once
// A node's view of the site configuration: every read is checked against the schema (type, range,
// default) and against the node's declared reads, so a node cannot read a key the schema does not
// list for it, and cannot refuse a value the schema (and so check_config) accepts.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "rascal_workcell/ParameterSchema.hpp"

namespace rascal_workcell {

class Parameters {
 public:
  /// `root` holds the configuration as loaded (the top-level sections of config/rascal.yaml);
  /// `reader` is the node's name as the schema's `readers` lists it.
  Parameters(YAML::Node root, std::string reader,
             const ParameterSchema& schema = ParameterSchema::builtin());
  /// Reads a YAML file (tests and tools); throws ParameterError when it cannot be read.
  static Parameters fromFile(const std::string& path, const std::string& reader,
                             const ParameterSchema& schema = ParameterSchema::builtin());

  // Each takes a concrete dotted key; a missing optional key gives the schema's default.
  // A wrong value throws ParameterError; a key the schema does not declare for this reader
  // throws std::logic_error (a programming error, caught by the node's wiring test).
  double number(const std::string& key) const;
  int integer(const std::string& key) const;
  bool flag(const std::string& key) const;
  std::string text(const std::string& key) const;  ///< string and enum
  std::vector<double> vector(const std::string& key) const;
  std::vector<std::vector<double>> vectors(const std::string& key) const;
  Eigen::Vector2d xy(const std::string& key) const;
  Eigen::Vector3d vector3(const std::string& key) const;
  /// Names under a `map` key (`stations`, `arm.named_poses`), in file order.
  std::vector<std::string> names(const std::string& key) const;
  bool has(const std::string& key) const;

  /// Schema keys declared for this reader that no call has read yet (with `*` as in the schema).
  std::vector<std::string> unread() const;
  /// Throws std::logic_error naming them when unread() is not empty: the README table and the
  /// schema would promise a parameter the node ignores.
  void checkAllRead() const;
  const std::string& reader() const { return reader_; }

 private:
  const ParameterSpec& spec(const std::string& key, const char* method) const;
  YAML::Node lookup(const std::string& key) const;
  YAML::Node valueOrDefault(const std::string& key, const ParameterSpec& s) const;
  double bound(const std::string& key, const ParameterSpec& s, bool upper) const;
  [[noreturn]] void fail(const std::string& key, const ParameterSpec& s, const YAML::Node& got) const;

  YAML::Node root_;
  std::string reader_;
  const ParameterSchema& schema_;
  mutable std::set<std::string> read_;  ///< schema keys read
};

}  // namespace rascal_workcell
