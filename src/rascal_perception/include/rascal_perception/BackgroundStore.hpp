#pragma once
// Station backgrounds kept on disk, one file per station, so that a detector started again (it
// crashed, or the rig was restarted mid-batch) still knows what each station looks like empty.
// Without them a restarted detector learns a killed run's sherd lying on the scale as background
// and the next batch never finds it; with them the batch's Calibrate sees it and keeps the model.
#include <string>

#include "rascal_perception/SherdDetector.hpp"

namespace rascal_perception {

class BackgroundStore {
 public:
  /// `dir` is created on the first save.
  explicit BackgroundStore(std::string dir) : dir_(std::move(dir)) {}

  /// `dir`/`station`.yml.gz
  std::string path(const std::string& station) const;
  /// Writes the station's background with the time it was learnt (`learnt_at`, s since the
  /// epoch) and `layout`, the station's place as configured then (any text that changes when
  /// the station or its fixtures move), replacing the file whole (a crash mid-write leaves the
  /// old one). Throws std::runtime_error naming the file; std::invalid_argument for a station
  /// without a model.
  void save(const SherdDetector& detector, const std::string& station, const std::string& layout,
            double learnt_at) const;
  /// Gives `detector` the station's background from its file when one is there, was learnt for
  /// the same `layout` and at most `max_age` s before `now`. True when restored; `message` says
  /// what happened either way ("" when there is no file).
  bool restore(SherdDetector& detector, const std::string& station, const std::string& layout, double now,
               double max_age, std::string& message) const;

 private:
  std::string dir_;
};

}  // namespace rascal_perception
