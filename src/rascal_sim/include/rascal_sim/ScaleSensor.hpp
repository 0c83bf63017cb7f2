#pragma once
// The digital scale's electronics: first-order settling, noise, 0.1 g readability, 10 Hz readings,
// a stability flag and tare (timing.md).
#include <deque>
#include <random>

namespace rascal_sim {

struct ScaleReading {
  double stamp = 0.0;   ///< [s]
  double mass = 0.0;    ///< [kg] tared, quantised to 1e-4 kg
  bool stable = false;
};

class ScaleSensor {
 public:
  static constexpr double kPeriod = 0.1;          ///< [s] 10 Hz
  static constexpr double kReadability = 1e-4;    ///< [kg] 0.1 g
  static constexpr double kNoiseSigma = 3e-5;     ///< [kg] 0.03 g
  static constexpr double kTimeConstant = 0.3;    ///< [s] settling
  static constexpr double kStableWindow = 0.5;    ///< [s]

  explicit ScaleSensor(unsigned seed = 1);
  /// Feeds the true load [kg] over dt; returns true when a new reading was made.
  bool update(double now, double dt, double load);
  const ScaleReading& latest() const { return latest_; }
  /// Sets zero to the present (filtered) load.
  void tare();
  /// Readings are garbage and unstable until `until`.
  void glitch(double until) { glitch_until_ = until; }
  void reset();

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> noise_{0.0, kNoiseSigma};
  double filtered_ = 0.0, tare_ = 0.0, next_reading_ = 0.0, glitch_until_ = -1.0;
  bool primed_ = false;
  std::deque<double> window_;
  ScaleReading latest_;
};

}  // namespace rascal_sim
