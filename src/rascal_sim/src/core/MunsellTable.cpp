#include "rascal_sim/MunsellTable.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rascal_sim {

namespace {
std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

int column(const std::vector<std::string>& header, const std::string& name, const std::string& path) {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  throw std::runtime_error("column " + name + " missing in " + path);
}
}  // namespace

MunsellTable::MunsellTable(const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) throw std::runtime_error("cannot read Munsell table " + csv_path);
  std::string line;
  std::getline(in, line);
  const auto header = splitCsv(line);
  const int name = column(header, "munsell", csv_path);
  const int r = column(header, "sRGB_R8", csv_path);
  while (std::getline(in, line)) {
    const auto cells = splitCsv(line);
    if (static_cast<int>(cells.size()) < r + 3) continue;
    Eigen::Vector3d c(std::stod(cells[r]), std::stod(cells[r + 1]), std::stod(cells[r + 2]));
    chips_[cells[name]] = c / 255.0;
    names_.push_back(cells[name]);
  }
  if (chips_.empty()) throw std::runtime_error("no chips in Munsell table " + csv_path);
}

bool MunsellTable::has(const std::string& notation) const { return chips_.count(notation) > 0; }

Eigen::Vector3d MunsellTable::srgb(const std::string& notation) const {
  auto it = chips_.find(notation);
  if (it == chips_.end()) throw std::out_of_range("unknown Munsell chip '" + notation + "'");
  return it->second;
}

std::vector<Eigen::Vector3d> MunsellTable::readColourChecker(const std::string& csv_path) {
  std::ifstream in(csv_path);
  if (!in) throw std::runtime_error("cannot read colour chart table " + csv_path);
  std::string line;
  std::getline(in, line);
  const auto header = splitCsv(line);
  const int r = column(header, "sRGB_R8", csv_path);
  std::vector<Eigen::Vector3d> patches;
  while (std::getline(in, line)) {
    const auto cells = splitCsv(line);
    if (static_cast<int>(cells.size()) < r + 3) continue;
    patches.emplace_back(std::stod(cells[r]) / 255.0, std::stod(cells[r + 1]) / 255.0,
                         std::stod(cells[r + 2]) / 255.0);
  }
  if (patches.size() != 24) throw std::runtime_error("expected 24 patches in " + csv_path);
  return patches;
}

}  // namespace rascal_sim
