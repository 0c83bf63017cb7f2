#pragma once
// Munsell soil-chart chips (renotation grid) and ColorChecker patches, read from the CSV files in
// the package's data folder.
#include <Eigen/Geometry>
#include <map>
#include <string>
#include <vector>

namespace rascal_sim {

class MunsellTable {
 public:
  /// Reads munsell_soil_hues_grid_renotation.csv; throws std::runtime_error naming the file.
  explicit MunsellTable(const std::string& csv_path);
  bool has(const std::string& notation) const;
  /// sRGB [0, 1] of a chip such as "2.5YR 6/6" or "N5"; throws std::out_of_range naming it.
  Eigen::Vector3d srgb(const std::string& notation) const;
  const std::vector<std::string>& notations() const { return names_; }

  /// The 24 ColorChecker patches (row-major, 4 x 6) as sRGB [0, 1] from a colorchecker24 CSV.
  static std::vector<Eigen::Vector3d> readColourChecker(const std::string& csv_path);

 private:
  std::map<std::string, Eigen::Vector3d> chips_;
  std::vector<std::string> names_;
};

}  // namespace rascal_sim
