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
