#include "rascal_workcell/ParameterServer.hpp"

#include <ros/param.h>

#include <algorithm>
#include <charconv>

namespace rascal_workcell {

namespace {

// The sections config/rascal.yaml puts at the root namespace (`rosparam load`).
std::vector<std::string> sections() {
  std::vector<std::string> out;
  for (const ParameterSpec& s : ParameterSchema::builtin().specs()) {
    const std::string top = s.key.substr(0, s.key.find('.'));
    if (std::find(out.begin(), out.end(), top) == out.end()) out.push_back(top);
  }
  return out;
}

YAML::Node toYaml(XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: return YAML::Node(static_cast<bool>(v) ? "true" : "false");
    case XmlRpc::XmlRpcValue::TypeInt: return YAML::Node(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble: {
      // The shortest text that reads back as the same double: 0.3, not 0.29999999999999999.
      char text[32];
      const auto end = std::to_chars(text, text + sizeof text, static_cast<double>(v)).ptr;
      return YAML::Node(std::string(text, end));
    }
    case XmlRpc::XmlRpcValue::TypeString: {
      YAML::Node n(static_cast<std::string>(v));
      n.SetTag("!");  // text, even when it looks like a number
      return n;
    }
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node n(YAML::NodeType::Sequence);
      for (int i = 0; i < v.size(); ++i) n.push_back(toYaml(v[i]));
      return n;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      YAML::Node n(YAML::NodeType::Map);
      for (auto it = v.begin(); it != v.end(); ++it) n[it->first] = toYaml(it->second);
      return n;
    }
    default: {
      YAML::Node n(std::string("<unsupported XmlRpc value>"));
      n.SetTag("!");
      return n;
    }
  }
}

}  // namespace

Parameters parametersFromServer(const std::string& reader) {
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& section : sections()) {
    XmlRpc::XmlRpcValue v;
    if (ros::param::get("/" + section, v)) root[section] = toYaml(v);
  }
  if (root.size() == 0) {
    throw ParameterError("no RASCAL configuration on the parameter server; run `rosparam load "
                         "config/rascal.yaml` first");
  }
  return Parameters(root, reader);
}

}  // namespace rascal_workcell
