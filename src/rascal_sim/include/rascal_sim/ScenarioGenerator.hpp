#pragma once
// Random scenarios: N irregular sherds on a station, seeded, spaced at least a finger apart; or
// a bag tipped out: the sherds dropped onto one spot, where they settle in layers (a heap).
#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/Scenario.hpp"
#include "rascal_sim/WorldLayout.hpp"

namespace rascal_sim {

struct GeneratorOptions {
  int count = 10;
  unsigned seed = 1;
  TableRect area;                    ///< where the sherds go (normally the pickup mat)
  double min_spacing = 0.016;        ///< [m] gap between neighbours: a finger (8 mm) and the grasp margin
  int touching_pairs = 0;            ///< pairs of sherds pushed together until they touch
  double length_min = 0.035, length_max = 0.070;  ///< [m] outline major axis
  double width_min = 0.032, width_max = 0.050;    ///< [m] outline minor axis (>= 30 mm gripper)
  double thickness_min = 0.004, thickness_max = 0.012;
  double density_min = 1800.0, density_max = 2000.0;
  double painted_fraction = 0.3;     ///< share of sherds with a painted pattern
  int mesh_count = 0;                ///< how many sherds use the fragment STL instead
  std::string mesh_file;
  // a heap (heap = true): every sherd dropped around heap_centre instead of laid on a grid
  bool heap = false;
  Eigen::Vector2d heap_centre{0.0, 0.0};  ///< [m] where the bag is tipped out (in `area`)
  double heap_spread = 0.03;          ///< [m] standard deviation of the sherds' centres about it
  double heap_drop_height = 0.02;     ///< [m] gap under the lowest sherds when they are let go
  int heap_layers = 3;                ///< no sherd is let go on more than layers - 1 others
};

class ScenarioGenerator {
 public:
  explicit ScenarioGenerator(const MunsellTable& munsell);
  std::vector<SherdSpec> generate(const GeneratorOptions& options) const;
  /// The sherds of `generate` re-placed as a heap: centres scattered about the heap's centre
  /// (kept on the area), each let go just above the sherds already dropped under it, so the
  /// pile is built at once without two sherds inside each other and settles in layers, at
  /// most heap_layers deep.
  static void heapUp(std::vector<SherdSpec>& sherds, const std::vector<Eigen::Vector2d>& extents,
                     const GeneratorOptions& o, std::mt19937& rng);
  /// An irregular outline with extents length x width, centred on its bounding box.
  static std::vector<Eigen::Vector2d> irregularOutline(double length, double width, std::mt19937& rng);

 private:
  const MunsellTable& munsell_;
};

}  // namespace rascal_sim
