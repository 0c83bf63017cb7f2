#include "rascal_workcell/ParameterSchema.hpp"

#include <algorithm>
#include <set>
#include <sstream>

namespace rascal_workcell {

extern const char* const kSchemaText;  // SchemaText.cpp, generated from schema/parameters.yaml

namespace {

const std::set<std::string> kTypes = {"number", "integer", "bool",        "string",
                                      "enum",   "vector",  "vector_list", "map"};
const std::set<std::string> kFields = {
    "type",   "unit",        "description", "min",           "max",           "exclusive_min",
    "length", "inner_length", "max_length", "choices",       "station_types", "required_names",
    "readers", "required",   "default",     "shape"};

std::vector<std::string> split(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

std::vector<std::string> strings(const YAML::Node& n) {
  std::vector<std::string> out;
  for (const auto& e : n) out.push_back(e.as<std::string>());
  return out;
}

// A bound is a number, a list of per-element numbers (vectors check each element against its
// own) or the name of another key.
void readBound(const YAML::Node& n, std::optional<double>& value, std::string& key,
               std::vector<double>& each) {
  if (!n) return;
  if (n.IsSequence()) {
    for (const auto& e : n) each.push_back(e.as<double>());
    value = *std::min_element(each.begin(), each.end());
    return;
  }
  try {
    value = n.as<double>();
  } catch (const YAML::Exception&) {
    key = n.as<std::string>();
  }
}

std::string number(double v) {
  std::ostringstream ss;
  ss << v;
  return ss.str();
}

std::string unitWords(const std::string& unit) {
  if (unit == "m") return "metres";
  if (unit == "s") return "seconds";
  if (unit == "rad") return "radians";
  if (unit == "px") return "pixels";
  return unit;
}

}  // namespace

bool keyMatches(const std::string& pattern, const std::string& key) {
  const auto p = split(pattern), k = split(key);
  if (p.size() != k.size()) return false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] != "*" && p[i] != k[i]) return false;
  }
  return true;
}

bool ParameterSpec::readBy(const std::string& reader) const {
  return std::find(readers.begin(), readers.end(), reader) != readers.end();
}

std::string ParameterSpec::expectation() const {
  const std::string in_unit = unit.empty() ? "" : " in " + unitWords(unit);
  auto range = [&]() {
    const std::string lo = !min_key.empty() ? min_key : (min ? number(*min) : "-inf");
    const std::string hi = !max_key.empty() ? max_key : (max ? number(*max) : "inf");
    return std::string(exclusive_min ? " in (" : " in [") + lo + ", " + hi + "]";
  };
  if (type == "number") return "a number" + in_unit + range();
  if (type == "integer") return "an integer" + in_unit + range();
  if (type == "bool") return "true or false";
  if (type == "string") return "a non-empty one-line string";
  if (type == "enum") {
    std::string s = "one of ";
    for (std::size_t i = 0; i < choices.size(); ++i) s += (i ? ", " : "") + choices[i];
    return s;
  }
  if (type == "vector" || type == "vector_list") return shape + in_unit;
  return "a mapping of names";
}

ParameterSchema ParameterSchema::fromYaml(const std::string& text) {
  ParameterSchema schema;
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(std::string("parameter schema: not valid YAML: ") + e.what());
  }
  if (!root.IsMap()) throw std::invalid_argument("parameter schema: expected a mapping of keys");
  for (const auto& entry : root) {
    ParameterSpec s;
    s.key = entry.first.as<std::string>();
    const YAML::Node& n = entry.second;
    auto bad = [&](const std::string& why) {
      throw std::invalid_argument("parameter schema: " + s.key + ": " + why);
    };
    if (!n.IsMap()) bad("expected a mapping of fields");
    for (const auto& f : n) {
      if (!kFields.count(f.first.as<std::string>())) bad("unknown field " + f.first.as<std::string>());
    }
    if (!n["type"] || !kTypes.count(n["type"].as<std::string>())) bad("missing or unknown type");
    s.type = n["type"].as<std::string>();
    s.unit = n["unit"] ? n["unit"].as<std::string>() : "";
    s.description = n["description"] ? n["description"].as<std::string>() : "";
    readBound(n["min"], s.min, s.min_key, s.min_each);
    readBound(n["max"], s.max, s.max_key, s.max_each);
    s.exclusive_min = n["exclusive_min"] && n["exclusive_min"].as<bool>();
    s.length = n["length"] ? n["length"].as<int>() : 0;
    s.inner_length = n["inner_length"] ? n["inner_length"].as<int>() : 0;
    s.max_length = n["max_length"] ? n["max_length"].as<int>() : 0;
    s.shape = n["shape"] ? n["shape"].as<std::string>() : "";
    if (n["choices"]) s.choices = strings(n["choices"]);
    if (n["station_types"]) s.station_types = strings(n["station_types"]);
    if (n["required_names"]) s.required_names = strings(n["required_names"]);
    if (n["readers"]) s.readers = strings(n["readers"]);
    s.required = n["required"] && n["required"].as<bool>();
    const bool has_default = n["default"].IsDefined();
    if (has_default) s.default_value = n["default"];
    if (s.required == has_default) bad("needs either required: true or a default");
    if (s.readers.empty()) bad("no readers");
    if (s.type == "enum" && s.choices.empty()) bad("enum without choices");
    schema.specs_.push_back(std::move(s));
  }
  return schema;
}

const ParameterSchema& ParameterSchema::builtin() {
  static const ParameterSchema schema = fromYaml(kSchemaText);
  return schema;
}

const ParameterSpec* ParameterSchema::find(const std::string& key) const {
  for (const ParameterSpec& s : specs_) {
    if (keyMatches(s.key, key)) return &s;
  }
  return nullptr;
}

}  // namespace rascal_workcell
