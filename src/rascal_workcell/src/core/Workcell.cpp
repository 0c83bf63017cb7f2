#include "rascal_workcell/Workcell.hpp"

#include <stdexcept>

namespace rascal_workcell {

std::string toString(StationType type) {
  switch (type) {
    case StationType::Pickup: return "pickup";
    case StationType::Scale: return "scale";
    case StationType::ArchivalCamera: return "archival_camera";
    case StationType::Discard: return "discard";
    case StationType::Bin: return "bin";
    case StationType::Other: return "other";
  }
  return "unknown";
}

StationType stationTypeFromString(const std::string& name) {
  for (StationType t : {StationType::Pickup, StationType::Scale, StationType::ArchivalCamera,
                        StationType::Discard, StationType::Bin}) {
    if (toString(t) == name) return t;
  }
  return StationType::Other;
}

bool TableRect::contains(const Eigen::Vector2d& p) const {
  return ((p - centre).cwiseAbs() - size / 2.0).maxCoeff() <= 1e-9;
}

Workcell Workcell::fromParameters(const Parameters& p) {
  Workcell w;
  for (const std::string& name : p.names("stations")) {
    const std::string key = "stations." + name + ".";
    auto rect = [&](const std::string& prefix) {
      return TableRect{p.xy(key + prefix + "position"), p.xy(key + prefix + "size")};
    };
    Station s;
    s.name = name;
    s.type = stationTypeFromString(p.text(key + "type"));
    s.area = rect("");
    s.surface_z = p.number(key + "surface_z");
    s.place_at = s.area.centre;
    if (s.type == StationType::ArchivalCamera) {
      s.place_at = p.xy(key + "place_at");
      s.camera_height = p.number(key + "camera_height");
      s.colour_chart = rect("colour_chart.");
      s.scale_bar = rect("scale_bar.");
      s.stand = rect("stand.");
      s.stand_height = p.number(key + "stand.height");
    } else if (s.type == StationType::Discard || s.type == StationType::Bin) {
      s.wall_height = p.number(key + "wall_height");
      if ((s.area.size.array() <= 2.0 * kDiscardWallThickness).any()) {
        throw ParameterError(key + "size: the box must be wider than its two walls (" +
                             std::to_string(2.0 * kDiscardWallThickness) + " m)");
      }
    }
    w.stations_.push_back(s);
  }
  for (StationType t : {StationType::Pickup, StationType::Scale, StationType::ArchivalCamera,
                        StationType::Discard}) {
    w.station(t);  // exactly one of each
  }
  return w;
}

const Station& Workcell::station(StationType type) const {
  const Station* found = nullptr;
  for (const Station& s : stations_) {
    if (s.type != type) continue;
    if (found) {
      throw ParameterError("stations: expected exactly one station of type " + toString(type) +
                           ", got " + found->name + " and " + s.name);
    }
    found = &s;
  }
  if (!found) throw ParameterError("stations: expected exactly one station of type " + toString(type));
  return *found;
}

const Station* Workcell::find(const std::string& name) const {
  for (const Station& s : stations_) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

std::vector<FixtureBox> Workcell::collisionBoxes() const {
  std::vector<FixtureBox> boxes;
  for (const Station& s : stations_) {
    const Eigen::Vector2d& c = s.area.centre;
    const Eigen::Vector2d& d = s.area.size;
    switch (s.type) {
      case StationType::Scale: {
        // The housing under the platform reaches beyond it; the platform on top is a support.
        const double housing = s.surface_z - kScalePlatformThickness;
        if (housing > 0.0) {
          boxes.push_back({"scale housing", s.name, {c.x(), c.y(), housing / 2.0},
                           {d.x() + 2 * kScaleHousingMargin, d.y() + 2 * kScaleHousingMargin, housing},
                           false});
        }
        const double thickness = std::min(kScalePlatformThickness, s.surface_z);
        if (thickness > 0.0) {
          boxes.push_back({"scale platform", s.name, {c.x(), c.y(), s.surface_z - thickness / 2.0},
                           {d.x(), d.y(), thickness}, true});
        }
        break;
      }
      case StationType::Discard:
      case StationType::Bin: {
        // Four walls centred on the box outline; the long ones overlap the corners.
        const double w = kDiscardWallThickness, h = s.wall_height;
        if (h <= 0.0) break;
        const std::string box = s.type == StationType::Bin ? "bin " + s.name : "discard box";
        boxes.push_back({box + " wall +y", s.name, {c.x(), c.y() + d.y() / 2, h / 2}, {d.x() + w, w, h}, false});
        boxes.push_back({box + " wall -y", s.name, {c.x(), c.y() - d.y() / 2, h / 2}, {d.x() + w, w, h}, false});
        boxes.push_back({box + " wall +x", s.name, {c.x() + d.x() / 2, c.y(), h / 2}, {w, d.y() + w, h}, false});
        boxes.push_back({box + " wall -x", s.name, {c.x() - d.x() / 2, c.y(), h / 2}, {w, d.y() + w, h}, false});
        break;
      }
      case StationType::ArchivalCamera:
        boxes.push_back({"camera stand", s.name, {s.stand.centre.x(), s.stand.centre.y(), s.stand_height / 2},
                         {s.stand.size.x(), s.stand.size.y(), s.stand_height}, false});
        break;
      case StationType::Pickup:
      case StationType::Other:
        break;  // a mat on the table
    }
  }
  return boxes;
}

std::vector<TableRect> Workcell::flatFixtures() const {
  std::vector<TableRect> out;
  for (const Station& s : stations_) {
    if (s.type == StationType::ArchivalCamera) {
      out.push_back(s.colour_chart);
      out.push_back(s.scale_bar);
    }
  }
  return out;
}

}  // namespace rascal_workcell
