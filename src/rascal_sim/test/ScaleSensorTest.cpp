#include <gtest/gtest.h>

#include <cmath>

#include "rascal_sim/ScaleSensor.hpp"

using rascal_sim::ScaleSensor;

TEST(ScaleSensor, SettlesToTheLoadWithinReadability) {
  ScaleSensor scale(3);
  const double dt = 0.001;
  int readings = 0;
  for (int i = 0; i < 3000; ++i) {
    const double load = i < 500 ? 0.0 : 0.02537;
    readings += scale.update(i * dt, dt, load);
  }
  EXPECT_NEAR(readings, 30, 1);
  EXPECT_NEAR(scale.latest().mass, 0.02537, 1e-4);
  EXPECT_TRUE(scale.latest().stable);
  EXPECT_NEAR(std::fmod(scale.latest().mass / 1e-4 + 1e-6, 1.0), 0.0, 1e-3);  // quantised
}

TEST(ScaleSensor, IsNotStableRightAfterALoadChange) {
  ScaleSensor scale(3);
  const double dt = 0.001;
  for (int i = 0; i < 2000; ++i) scale.update(i * dt, dt, 0.0);
  for (int i = 2000; i < 2300; ++i) scale.update(i * dt, dt, 0.050);
  EXPECT_FALSE(scale.latest().stable);
  EXPECT_LT(scale.latest().mass, 0.050);
}

TEST(ScaleSensor, TareZeroesThePresentLoad) {
  ScaleSensor scale(3);
  const double dt = 0.001;
  for (int i = 0; i < 3000; ++i) scale.update(i * dt, dt, 0.1);
  scale.tare();
  for (int i = 3000; i < 4000; ++i) scale.update(i * dt, dt, 0.1);
  EXPECT_NEAR(scale.latest().mass, 0.0, 1e-4);
}

namespace {
// Steps `scale` from `t` for `seconds` under `load` at 1 kHz; returns the time reached.
double run(ScaleSensor& scale, double t, double seconds, double load) {
  const double dt = 0.001;
  const int n = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < n; ++i) {
    t += dt;
    scale.update(t, dt, load);
  }
  return t;
}
}  // namespace

TEST(ScaleSensor, UnsettledTareDriftsLowThenReadsLowAndStable) {
  ScaleSensor scale(5);
  double t = run(scale, 0.0, 3.0, 0.0);
  scale.unsettledNextTare(2.0);
  t = run(scale, t, 1.0, 0.0);  // armed only: nothing changes before the tare
  EXPECT_NEAR(scale.latest().mass, 0.0, 1e-4);
  EXPECT_TRUE(scale.latest().stable);
  scale.tare();
  bool stable_while_drifting = false;
  const double dt = 0.001;
  for (int i = 0; i < 1800; ++i) {
    t += dt;
    if (scale.update(t, dt, 0.0) && i > 600) stable_while_drifting |= scale.latest().stable;
  }
  EXPECT_FALSE(stable_while_drifting);
  t = run(scale, t, 2.0, 0.0);
  EXPECT_NEAR(scale.latest().mass, -ScaleSensor::kUnsettledTareError, 1e-4);  // empty reads -3 g
  EXPECT_TRUE(scale.latest().stable);
  t = run(scale, t, 3.0, 0.0139);
  EXPECT_NEAR(scale.latest().mass, 0.0139 - ScaleSensor::kUnsettledTareError, 1e-4);
  EXPECT_TRUE(scale.latest().stable) << "the device calls the 3 g low mass stable";
  scale.tare();  // a second tare on the settled platform is right again
  t = run(scale, t, 1.0, 0.0139);
  EXPECT_NEAR(scale.latest().mass, 0.0, 1e-4);
}

TEST(ScaleSensor, GlitchOnLoadStartsWhenTheNextLoadLands) {
  ScaleSensor scale(5);
  double t = run(scale, 0.0, 2.0, 0.0);
  scale.glitchOnNextLoad(3.0);
  t = run(scale, t, 2.0, 0.0);  // nothing on the pan: no glitch yet
  EXPECT_TRUE(scale.latest().stable);
  const double dt = 0.001;
  bool any_stable = false;
  for (int i = 0; i < 2900; ++i) {  // the sherd lands; 2.9 s of garbage
    t += dt;
    if (scale.update(t, dt, 0.0139)) any_stable |= scale.latest().stable;
  }
  EXPECT_FALSE(any_stable);
  t = run(scale, t, 1.5, 0.0139);  // the glitch is over
  EXPECT_TRUE(scale.latest().stable);
  EXPECT_NEAR(scale.latest().mass, 0.0139, 1e-4);
  t = run(scale, t, 1.0, 0.0);  // lifted off and put back: the fault was used up
  t = run(scale, t, 2.0, 0.0139);
  EXPECT_TRUE(scale.latest().stable);
}

TEST(ScaleSensor, ClearFaultsDisarmsThem) {
  ScaleSensor scale(5);
  double t = run(scale, 0.0, 2.0, 0.0);
  scale.glitchOnNextLoad(3.0);
  scale.unsettledNextTare(2.0);
  scale.clearFaults();
  scale.tare();
  t = run(scale, t, 2.0, 0.0139);
  EXPECT_TRUE(scale.latest().stable);
  EXPECT_NEAR(scale.latest().mass, 0.0139, 1e-4);
}
