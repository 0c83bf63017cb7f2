#include "rascal_sim/ScaleSensor.hpp"

#include <algorithm>
#include <cmath>

namespace rascal_sim {

ScaleSensor::ScaleSensor(unsigned seed) : rng_(seed) {}

void ScaleSensor::reset() {
  filtered_ = 0.0;
  tare_ = 0.0;
  next_reading_ = 0.0;
  now_ = 0.0;
  swing_start_ = swing_duration_ = 0.0;
  clearFaults();
  primed_ = false;
  loaded_ = false;
  window_.clear();
  latest_ = ScaleReading();
}

void ScaleSensor::clearFaults() {
  glitch_until_ = -1.0;
  glitch_on_load_ = 0.0;
  unsettled_tare_ = 0.0;
}

void ScaleSensor::tare() {
  tare_ = filtered_;
  if (unsettled_tare_ > 0.0) {
    tare_ += kUnsettledTareError;
    swing_start_ = now_;
    swing_duration_ = unsettled_tare_;
    unsettled_tare_ = 0.0;
  }
}

bool ScaleSensor::update(double now, double dt, double load) {
  if (!primed_) {
    filtered_ = load;
    primed_ = true;
  } else {
    filtered_ += (load - filtered_) * (1.0 - std::exp(-dt / kTimeConstant));
  }
  now_ = now;
  const bool loaded = load > kLoadedAbove;
  if (loaded && !loaded_ && glitch_on_load_ > 0.0) {
    glitch_until_ = now + glitch_on_load_;
    glitch_on_load_ = 0.0;
  }
  loaded_ = loaded;
  if (now + 1e-9 < next_reading_) return false;
  next_reading_ = std::max(next_reading_ + kPeriod, now);
  double value = filtered_ - tare_ + noise_(rng_);
  if (now < swing_start_ + swing_duration_) {  // the swing a tare caught dies away
    value += kUnsettledTareError * (1.0 - (now - swing_start_) / swing_duration_);
  }
  const bool glitching = now < glitch_until_;
  if (glitching) value += std::uniform_real_distribution<double>(-0.05, 0.05)(rng_);
  value = std::round(value / kReadability) * kReadability;
  window_.push_back(value);
  const size_t n = static_cast<size_t>(std::lround(kStableWindow / kPeriod)) + 1;
  while (window_.size() > n) window_.pop_front();
  bool stable = !glitching && window_.size() == n;
  for (double w : window_) {
    if (std::abs(w - value) > kReadability + 1e-9) stable = false;
  }
  latest_ = {now, value, stable};
  return true;
}

}  // namespace rascal_sim
