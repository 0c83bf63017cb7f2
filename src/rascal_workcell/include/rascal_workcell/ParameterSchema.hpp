#pragma once
// The parameter schema (schema/parameters.yaml, compiled in): for every key of config/rascal.yaml
// its type, unit, range, default, description and the nodes that read it. The one source of
// truth that the Python validator (check_config), every C++ node and every README table follow.
#include <yaml-cpp/yaml.h>

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rascal_workcell {

/// A parameter value is wrong; what() is one line naming the key, what is expected and the value.
class ParameterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One entry of the schema. `key` is dotted and may hold `*` for a name chosen by the site
/// (`stations.*.position`, `arm.named_poses.*`).
struct ParameterSpec {
  std::string key;
  std::string type;         ///< number | integer | bool | string | enum | vector | vector_list | map
  std::string unit;         ///< SI unit ("m", "s", "rad", "Hz", "px", "kg") or empty
  std::string description;
  std::optional<double> min, max;  ///< inclusive bounds (numbers, integers, vector elements)
  std::string min_key, max_key;    ///< bounds taken from another key's value
  bool exclusive_min = false;
  int length = 0;                  ///< vector: elements; vector_list: vectors
  int inner_length = 0;            ///< vector_list: elements of each vector
  int max_length = 0;              ///< string: characters
  std::string shape;               ///< how a vector is written ("[x, y]"), quoted in errors
  std::vector<double> min_each, max_each;  ///< vectors: per-element bounds when given as lists
  std::vector<std::string> choices;        ///< enum
  std::vector<std::string> station_types;  ///< only under stations of these types (empty: all)
  std::vector<std::string> required_names; ///< map: names that must be present
  std::vector<std::string> readers;        ///< nodes that read it: sim, arm_controller, ...
  bool required = false;
  YAML::Node default_value;                ///< null when required

  bool readBy(const std::string& reader) const;
  /// "a number in m in [0, 0.2]" — the expectation quoted in errors and README tables.
  std::string expectation() const;
};

class ParameterSchema {
 public:
  /// The schema compiled into this library from schema/parameters.yaml.
  static const ParameterSchema& builtin();
  /// Throws std::invalid_argument when the schema text itself is malformed.
  static ParameterSchema fromYaml(const std::string& text);

  /// The entry matching a concrete dotted key (`stations.scale.surface_z` matches
  /// `stations.*.surface_z`); nullptr when none.
  const ParameterSpec* find(const std::string& key) const;
  const std::vector<ParameterSpec>& specs() const { return specs_; }

 private:
  std::vector<ParameterSpec> specs_;
};

/// Whether a dotted key matches a schema key with `*` wildcards (one name each).
bool keyMatches(const std::string& pattern, const std::string& key);

}  // namespace rascal_workcell
