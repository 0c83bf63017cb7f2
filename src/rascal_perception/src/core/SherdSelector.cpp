#include "rascal_perception/SherdSelector.hpp"

#include <algorithm>
#include <stdexcept>

namespace rascal_perception {

SelectionPolicy parseSelectionPolicy(const std::string& name) {
  if (name == "nearest") return SelectionPolicy::kNearest;
  if (name == "largest") return SelectionPolicy::kLargest;
  if (name == "most_isolated") return SelectionPolicy::kMostIsolated;
  throw std::invalid_argument("unknown selection policy '" + name + "' (nearest | largest | most_isolated)");
}

void SherdSelector::order(std::vector<SherdDetection>& sherds, SelectionPolicy policy,
                          const Eigen::Vector2d& reference) {
  auto key = [&](const SherdDetection& s) {
    switch (policy) {
      case SelectionPolicy::kLargest:
        return -s.area;
      case SelectionPolicy::kMostIsolated:
        return -s.clearance;
      case SelectionPolicy::kNearest:
      default:
        return (s.centre.head<2>() - reference).norm();
    }
  };
  std::stable_sort(sherds.begin(), sherds.end(),
                   [&](const SherdDetection& a, const SherdDetection& b) { return key(a) < key(b); });
}

}  // namespace rascal_perception
