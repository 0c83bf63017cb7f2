#pragma once
// The one bridge from the ROS parameter server to Parameters: the schema's top-level sections,
// converted from XmlRpc to YAML once. Node wrappers call this; cores never see ROS.
#include <string>

#include "rascal_workcell/Parameters.hpp"

namespace rascal_workcell {

/// The configuration as loaded with `rosparam load config/rascal.yaml` (at the root namespace),
/// for `reader`. Throws ParameterError when a section is missing.
Parameters parametersFromServer(const std::string& reader);

}  // namespace rascal_workcell
