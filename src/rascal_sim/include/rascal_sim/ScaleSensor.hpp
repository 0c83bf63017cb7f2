#pragma once
// The digital scale's electronics: first-order settling, noise, 0.1 g readability, 10 Hz readings,
// a stability flag and tare (timing.md); and its faults for tests (garbage readings, a tare taken
// while the platform still swings).
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
  static constexpr double kLoadedAbove = 1e-3;    ///< [kg] a load above this has landed on the pan
  static constexpr double kUnsettledTareError = 3e-3;  ///< [kg] zero error of an unsettled tare

  explicit ScaleSensor(unsigned seed = 1);
  /// Feeds the true load [kg] over dt; returns true when a new reading was made.
  bool update(double now, double dt, double load);
  const ScaleReading& latest() const { return latest_; }
  /// Sets zero to the present (filtered) load.
  void tare();
  /// Readings are garbage and unstable until `until`.
  void glitch(double until) { glitch_until_ = until; }
  /// Readings are garbage and unstable for `duration` from when a load next lands on the pan
  /// (the load rises above kLoadedAbove): the fault hits the next sherd put on the scale.
  void glitchOnNextLoad(double duration) { glitch_on_load_ = duration; }
  /// The next tare() catches the platform still swinging kUnsettledTareError high: zero is set
  /// that much too high, and the readings drift that much low over `duration` (unstable while
  /// they drift), then read low, stable, until the next tare.
  void unsettledNextTare(double duration) { unsettled_tare_ = duration; }
  /// Ends a glitch and disarms the faults waiting for a load or a tare.
  void clearFaults();
  void reset();

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> noise_{0.0, kNoiseSigma};
  double filtered_ = 0.0, tare_ = 0.0, next_reading_ = 0.0, glitch_until_ = -1.0;
  double now_ = 0.0;
  double glitch_on_load_ = 0.0, unsettled_tare_ = 0.0;  ///< [s] armed faults (0: none)
  double swing_start_ = 0.0, swing_duration_ = 0.0;     ///< the swing of an unsettled tare
  bool primed_ = false, loaded_ = false;
  std::deque<double> window_;
  ScaleReading latest_;
};

}  // namespace rascal_sim
