#pragma once
// Reads a scenario YAML (explicit sherds and/or a `generate:` block) into a Scenario.
#include <string>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/Scenario.hpp"
#include "rascal_sim/WorldLayout.hpp"

namespace rascal_sim {

class ScenarioLoader {
 public:
  ScenarioLoader(const WorldLayout& layout, const MunsellTable& munsell);
  /// Parses YAML text; throws std::runtime_error with a one-line reason naming the key.
  Scenario parse(const std::string& yaml_text) const;
  Scenario load(const std::string& path) const;

 private:
  const WorldLayout& layout_;
  const MunsellTable& munsell_;
};

}  // namespace rascal_sim
