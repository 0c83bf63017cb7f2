#include "rascal_sim/ScenarioLoader.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

#include "rascal_sim/ScenarioGenerator.hpp"

namespace rascal_sim {

namespace {
[[noreturn]] void fail(const std::string& key, const std::string& why) {
  throw std::runtime_error("scenario key '" + key + "': " + why);
}

double number(const YAML::Node& node, const std::string& key, double def, double lo, double hi) {
  if (!node) return def;
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a number");
  }
  if (v < lo || v > hi) {
    std::ostringstream ss;
    ss << "value " << v << " outside [" << lo << ", " << hi << "]";
    fail(key, ss.str());
  }
  return v;
}

std::vector<double> numbers(const YAML::Node& node, const std::string& key, size_t n) {
  if (!node.IsSequence() || node.size() != n) fail(key, "expected a list of " + std::to_string(n) + " numbers");
  std::vector<double> v;
  for (const auto& x : node) {
    try {
      v.push_back(x.as<double>());
    } catch (const YAML::Exception&) {
      fail(key, "expected numbers");
    }
  }
  return v;
}

/// A station's area by its type (`camera` is the archival camera's), never by the site's name
/// for it, where the scenario has it really stand.
TableRect station(const WorldLayout& l, const std::map<std::string, StationOffset>& offsets,
                  const std::string& type, const std::string& key) {
  StationType t = StationType::Pickup;
  try {
    t = rascal_workcell::stationTypeFromString(type == "camera" ? "archival_camera" : type);
  } catch (const std::invalid_argument&) {
    fail(key, "unknown station type '" + type + "' (pickup, scale, camera, discard)");
  }
  const Station& s = l.station(t);
  TableRect area = s.area;
  const auto o = offsets.find(s.name);
  if (o != offsets.end()) {
    area.centre += Eigen::Vector2d(o->second.dx, o->second.dy);
    area.yaw += o->second.dyaw;
  }
  return area;
}

/// `station_offsets`: station name -> [dx, dy, dyaw], each within StationOffset's limits.
std::map<std::string, StationOffset> stationOffsets(const YAML::Node& node, const WorldLayout& l) {
  std::map<std::string, StationOffset> offsets;
  if (!node) return offsets;
  if (!node.IsMap()) fail("station_offsets", "expected a mapping of station name to [dx, dy, dyaw]");
  for (const auto& kv : node) {
    const std::string name = kv.first.as<std::string>();
    const std::string key = "station_offsets." + name;
    if (!l.find(name)) {
      std::string known;
      for (const Station& s : l.stations) known += (known.empty() ? "" : ", ") + s.name;
      fail(key, "no such station (" + known + ")");
    }
    const auto v = numbers(kv.second, key, 3);
    if (std::abs(v[0]) > StationOffset::kMaxShift || std::abs(v[1]) > StationOffset::kMaxShift ||
        std::abs(v[2]) > StationOffset::kMaxTurn) {
      std::ostringstream ss;
      ss << "[dx, dy, dyaw] = [" << v[0] << ", " << v[1] << ", " << v[2] << "] outside ±" << StationOffset::kMaxShift
         << " m, ±" << StationOffset::kMaxShift << " m, ±" << StationOffset::kMaxTurn << " rad";
      fail(key, ss.str());
    }
    offsets[name] = {v[0], v[1], v[2]};
  }
  return offsets;
}
}  // namespace

ScenarioLoader::ScenarioLoader(const WorldLayout& layout, const MunsellTable& munsell)
    : layout_(layout), munsell_(munsell) {}

Scenario ScenarioLoader::load(const std::string& path) const {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read scenario file " + path);
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str());
}

Scenario ScenarioLoader::parse(const std::string& yaml_text) const {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(std::string("scenario is not valid YAML: ") + e.what());
  }
  if (!root.IsMap()) throw std::runtime_error("scenario must be a YAML mapping");
  Scenario s;
  if (root["name"]) s.name = root["name"].as<std::string>();
  s.seed = static_cast<unsigned>(number(root["seed"], "seed", 1, 0, 4e9));
  const YAML::Node light = root["lighting"];
  if (light) {
    Lighting& l = s.lighting;
    l.brightness = number(light["brightness"], "lighting.brightness", 1.0, 0.3, 1.5);
    l.colour_temperature = number(light["colour_temperature"], "lighting.colour_temperature", 6500, 2500, 10000);
    l.colour_noise = number(light["colour_noise"], "lighting.colour_noise", 2.0, 0.0, 20.0);
    const YAML::Node re = light["realism"];
    if (re) {
      Realism& r = l.realism;
      r.texture = number(re["texture"], "lighting.realism.texture", 1.0, 0.0, 1.0);
      r.cast_shadow = number(re["cast_shadow"], "lighting.realism.cast_shadow", 0.5, 0.0, 0.8);
      r.glare = number(re["glare"], "lighting.realism.glare", 0.5, 0.0, 1.0);
      r.light_azimuth = number(re["light_azimuth"], "lighting.realism.light_azimuth", r.light_azimuth, -M_PI, M_PI);
      r.light_elevation =
          number(re["light_elevation"], "lighting.realism.light_elevation", r.light_elevation, 0.3, M_PI / 2);
    }
    const YAML::Node sh = light["shadow"];
    if (sh) {
      l.shadow_strength = number(sh["strength"], "lighting.shadow.strength", 0.4, 0.0, 0.8);
      l.shadow_radius = number(sh["radius"], "lighting.shadow.radius", 0.08, 0.005, 1.0);
      if (sh["start"]) {
        const auto v = numbers(sh["start"], "lighting.shadow.start", 2);
        l.shadow_start = {v[0], v[1]};
      }
      if (sh["velocity"]) {
        const auto v = numbers(sh["velocity"], "lighting.shadow.velocity", 2);
        l.shadow_velocity = {v[0], v[1]};
      }
    }
  }
  s.station_offsets = stationOffsets(root["station_offsets"], layout_);
  const std::string fragment = layout_.data_dir + "/archaide_braccio_frag_1.stl";
  const YAML::Node gen = root["generate"];
  if (gen) {
    GeneratorOptions o;
    o.count = static_cast<int>(number(gen["count"], "generate.count", 10, 0, 200));
    o.seed = static_cast<unsigned>(number(gen["seed"], "generate.seed", s.seed, 0, 4e9));
    o.area = station(layout_, s.station_offsets, gen["station"] ? gen["station"].as<std::string>() : "pickup",
                     "generate.station");
    o.min_spacing = number(gen["min_spacing"], "generate.min_spacing", o.min_spacing, 0.0, 0.1);
    o.touching_pairs = static_cast<int>(number(gen["touching_pairs"], "generate.touching_pairs", 0, 0, 100));
    o.painted_fraction = number(gen["painted_fraction"], "generate.painted_fraction", o.painted_fraction, 0, 1);
    o.mesh_count = static_cast<int>(number(gen["mesh_count"], "generate.mesh_count", 0, 0, 200));
    o.mesh_file = fragment;
    o.length_min = number(gen["length_min"], "generate.length_min", o.length_min, 0.015, 0.10);
    o.length_max = number(gen["length_max"], "generate.length_max", o.length_max, o.length_min, 0.10);
    o.width_min = number(gen["width_min"], "generate.width_min", o.width_min, 0.015, 0.10);
    o.width_max = number(gen["width_max"], "generate.width_max", o.width_max, o.width_min, 0.10);
    if (const YAML::Node heap = gen["heap"]) {
      // a bag tipped out: every generated sherd dropped around one spot (ScenarioGenerator)
      if (!heap.IsMap()) fail("generate.heap", "expected {centre: [x, y], spread: m, drop_height: m, layers: n}");
      o.heap = true;
      o.heap_centre = o.area.centre;
      if (heap["centre"]) {
        const auto v = numbers(heap["centre"], "generate.heap.centre", 2);
        o.heap_centre = {v[0], v[1]};
        if (!o.area.contains(o.heap_centre)) fail("generate.heap.centre", "must lie on the station it is tipped onto");
      }
      o.heap_spread = number(heap["spread"], "generate.heap.spread", o.heap_spread, 0.0, 0.2);
      o.heap_drop_height = number(heap["drop_height"], "generate.heap.drop_height", o.heap_drop_height, 0.0, 0.3);
      o.heap_layers = static_cast<int>(number(heap["layers"], "generate.heap.layers", o.heap_layers, 1, 10));
    }
    ScenarioGenerator g(munsell_);
    s.sherds = g.generate(o);
  }
  const YAML::Node list = root["sherds"];
  if (list) {
    if (!list.IsSequence()) fail("sherds", "expected a list");
    std::mt19937 rng(s.seed);
    for (size_t i = 0; i < list.size(); ++i) {
      const YAML::Node n = list[i];
      const std::string k = "sherds[" + std::to_string(i) + "]";
      SherdSpec sp;
      sp.name = n["name"] ? n["name"].as<std::string>() : "sherd_x" + std::to_string(i);
      if (!n["pose"]) fail(k + ".pose", "required: [x, y, yaw]");
      const auto pose = numbers(n["pose"], k + ".pose", 3);
      sp.pose = {pose[0], pose[1], pose[2]};
      sp.thickness = number(n["thickness"], k + ".thickness", 0.007, 0.002, 0.03);
      sp.curvature = number(n["curvature"], k + ".curvature", 0.0, -50, 50);
      sp.curvature_long = number(n["curvature_long"], k + ".curvature_long", 0.0, -50, 50);
      sp.convex_up = n["convex_up"] ? n["convex_up"].as<bool>() : true;
      sp.density = number(n["density"], k + ".density", 1850, 1000, 3000);
      sp.drop_height = number(n["drop_height"], k + ".drop_height", 0.0, 0.0, 0.5);
      sp.tilt = number(n["tilt"], k + ".tilt", 0.0, -M_PI, M_PI);
      if (n["munsell"]) {
        sp.munsell = n["munsell"].as<std::string>();
        if (!munsell_.has(sp.munsell)) fail(k + ".munsell", "unknown chip '" + sp.munsell + "'");
      }
      sp.colour = munsell_.has(sp.munsell) ? munsell_.srgb(sp.munsell) : sp.colour;
      if (n["pattern"]) {
        sp.pattern = n["pattern"].as<std::string>();
        if (sp.pattern != "none" && sp.pattern != "stripes" && sp.pattern != "band")
          fail(k + ".pattern", "expected none, stripes or band");
      }
      if (n["pattern_colour"]) {
        const auto c = numbers(n["pattern_colour"], k + ".pattern_colour", 3);
        sp.pattern_colour = {c[0], c[1], c[2]};
      }
      if (n["mesh"]) {
        const std::string m = n["mesh"].as<std::string>();
        sp.mesh_file = (m == "fragment") ? fragment : m;
      } else if (n["outline"]) {
        if (!n["outline"].IsSequence() || n["outline"].size() < 3) fail(k + ".outline", "expected >= 3 [x, y] points");
        for (size_t j = 0; j < n["outline"].size(); ++j) {
          const auto p = numbers(n["outline"][j], k + ".outline", 2);
          sp.outline.emplace_back(p[0], p[1]);
        }
      } else {
        const double length = number(n["length"], k + ".length", 0.05, 0.015, 0.10);
        const double width = number(n["width"], k + ".width", 0.04, 0.012, length);
        sp.outline = ScenarioGenerator::irregularOutline(length, width, rng);
      }
      s.sherds.push_back(sp);
    }
  }
  return s;
}

}  // namespace rascal_sim
