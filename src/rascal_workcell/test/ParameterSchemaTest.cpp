#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <functional>

#include "rascal_workcell/ParameterSchema.hpp"

using namespace rascal_workcell;

namespace {
// Every leaf of the shipped file (a map is walked, a sequence is a value) with its dotted key.
void leaves(const YAML::Node& n, const std::string& key, std::vector<std::pair<std::string, YAML::Node>>& out) {
  if (n.IsMap()) {
    for (const auto& e : n) leaves(e.second, key.empty() ? e.first.as<std::string>() : key + "." + e.first.as<std::string>(), out);
  } else {
    out.emplace_back(key, n);
  }
}
}  // namespace

TEST(ParameterSchema, BuiltinParsesAndEveryEntryHasReaders) {
  const auto& schema = ParameterSchema::builtin();
  EXPECT_GT(schema.specs().size(), 60u);
  for (const auto& s : schema.specs()) {
    EXPECT_FALSE(s.readers.empty()) << s.key;
    EXPECT_FALSE(s.description.empty()) << s.key;
  }
}

TEST(ParameterSchema, EveryShippedKeyIsInTheSchemaAndEveryDefaultIsTheShippedValue) {
  const YAML::Node shipped = YAML::LoadFile(RASCAL_CONFIG_PATH);
  std::vector<std::pair<std::string, YAML::Node>> all;
  leaves(shipped, "", all);
  ASSERT_GT(all.size(), 60u);
  for (const auto& [key, value] : all) {
    const ParameterSpec* s = ParameterSchema::builtin().find(key);
    ASSERT_NE(s, nullptr) << key << " is in config/rascal.yaml but not in the schema";
    // a null default is "none unless the site has one" (a station's calibration markers)
    if (!s->required && !s->default_value.IsNull()) {
      YAML::Emitter a, b;
      a << YAML::Flow << s->default_value;
      b << YAML::Flow << value;
      EXPECT_EQ(std::string(a.c_str()), std::string(b.c_str())) << key << ": schema default differs from the shipped file";
    }
  }
}

TEST(ParameterSchema, WildcardsMatchOneNameEach) {
  EXPECT_TRUE(keyMatches("stations.*.surface_z", "stations.balance.surface_z"));
  EXPECT_FALSE(keyMatches("stations.*.surface_z", "stations.a.b.surface_z"));
  EXPECT_FALSE(keyMatches("arm.travel_z", "arm.travel"));
  const ParameterSpec* s = ParameterSchema::builtin().find("stations.camera.stand.height");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->key, "stations.*.stand.height");
}

TEST(ParameterSchema, MalformedSchemaIsRefusedWithTheKey) {
  EXPECT_THROW(ParameterSchema::fromYaml("a.b: {type: number, readers: [x]}"), std::invalid_argument);  // neither required nor default
  EXPECT_THROW(ParameterSchema::fromYaml("a.b: {type: numbr, default: 1, readers: [x]}"), std::invalid_argument);
  EXPECT_THROW(ParameterSchema::fromYaml("a.b: {type: number, default: 1, readers: [x], rnage: 2}"), std::invalid_argument);
  try {
    ParameterSchema::fromYaml("a.b: {type: number, default: 1}");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("a.b"), std::string::npos);
  }
}
