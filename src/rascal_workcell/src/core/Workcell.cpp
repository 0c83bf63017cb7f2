#include "rascal_workcell/Workcell.hpp"

#include <Eigen/Geometry>
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
  return (toLocal(p).cwiseAbs() - size / 2.0).maxCoeff() <= 1e-9;
}

Eigen::Vector2d TableRect::toLocal(const Eigen::Vector2d& p) const {
  return Eigen::Rotation2Dd(-yaw) * (p - centre);
}

Eigen::Vector2d TableRect::toTable(const Eigen::Vector2d& local) const {
  return centre + Eigen::Rotation2Dd(yaw) * local;
}

Workcell Workcell::fromParameters(const Parameters& p) {
  Workcell w;
  for (const std::string& name : p.names("stations")) {
    const std::string key = "stations." + name + ".";
    const double yaw = p.number(key + "yaw");  // everything on a station turns with it
    auto rect = [&](const std::string& prefix) {
      return TableRect{p.xy(key + prefix + "position"), p.xy(key + prefix + "size"), yaw};
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
    const TableRect& a = s.area;
    const Eigen::Vector2d& d = a.size;
    // a box at `local` in the station's own frame, turned with it
    auto box = [&](const std::string& name, const Eigen::Vector2d& local, double z, const Eigen::Vector3d& size,
                   bool support) {
      const Eigen::Vector2d c = a.toTable(local);
      return FixtureBox{name, s.name, {c.x(), c.y(), z}, size, support, a.yaw};
    };
    switch (s.type) {
      case StationType::Scale: {
        // The housing under the platform reaches beyond it; the platform on top is a support.
        const double housing = s.surface_z - kScalePlatformThickness;
        if (housing > 0.0) {
          boxes.push_back(box("scale housing", {0, 0}, housing / 2.0,
                              {d.x() + 2 * kScaleHousingMargin, d.y() + 2 * kScaleHousingMargin, housing}, false));
        }
        const double thickness = std::min(kScalePlatformThickness, s.surface_z);
        if (thickness > 0.0) {
          boxes.push_back(box("scale platform", {0, 0}, s.surface_z - thickness / 2.0, {d.x(), d.y(), thickness}, true));
        }
        break;
      }
      case StationType::Discard:
      case StationType::Bin: {
        // Four walls centred on the box outline; the long ones overlap the corners.
        const double w = kDiscardWallThickness, h = s.wall_height;
        if (h <= 0.0) break;
        const std::string name = s.type == StationType::Bin ? "bin " + s.name : "discard box";
        boxes.push_back(box(name + " wall +y", {0, d.y() / 2}, h / 2, {d.x() + w, w, h}, false));
        boxes.push_back(box(name + " wall -y", {0, -d.y() / 2}, h / 2, {d.x() + w, w, h}, false));
        boxes.push_back(box(name + " wall +x", {d.x() / 2, 0}, h / 2, {w, d.y() + w, h}, false));
        boxes.push_back(box(name + " wall -x", {-d.x() / 2, 0}, h / 2, {w, d.y() + w, h}, false));
        break;
      }
      case StationType::ArchivalCamera:
        boxes.push_back({"camera stand", s.name, {s.stand.centre.x(), s.stand.centre.y(), s.stand_height / 2},
                         {s.stand.size.x(), s.stand.size.y(), s.stand_height}, false, s.stand.yaw});
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
