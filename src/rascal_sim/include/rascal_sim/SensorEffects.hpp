#pragma once
// What the camera adds to the rendered radiance: scenario lighting (brightness, colour
// temperature, a moving shadow), motion blur, colour noise, and the D435 depth noise model.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <random>

#include "rascal_sim/CameraModel.hpp"
#include "rascal_sim/Scenario.hpp"

namespace rascal_sim {

class SensorEffects {
 public:
  static constexpr double kDepthFocal = 382.6;     ///< [px] D435 depth at 640 x 480, facts §4.3
  static constexpr double kBaseline = 0.050;       ///< [m] facts §4.1
  static constexpr double kSubpixelSigma = 0.08;   ///< [px] facts §4.4 (unverified figure)
  static constexpr double kMinDepth = 0.105;       ///< [m] below this the D435 returns 0 (min-Z)

  explicit SensorEffects(unsigned seed = 1);
  /// Starts the noise over from `seed` (the table of samples stays; where it is read from is
  /// drawn again): the same scene loaded twice gives the same frames.
  void reseed(unsigned seed) { rng_.seed(seed); }
  /// White-balance gains of light at `kelvin` relative to 6500 K (sRGB primaries).
  static Eigen::Vector3d temperatureGains(double kelvin);
  /// sigma of the depth noise at distance z [m].
  static double depthSigma(double z) { return z * z * kSubpixelSigma / (kDepthFocal * kBaseline); }

  /// Linear gain of the scenario's light (brightness x colour temperature) for the renderer.
  static Eigen::Vector3f lightGain(const Lighting& lighting);
  /// Adds the moving shadow, motion blur and colour noise to a rendered sRGB image (in place).
  void colourImage(cv::Mat& colour, const cv::Mat& depth, const CameraModel& camera,
                   const Eigen::Isometry3d& world_T_camera, const Lighting& lighting, double t,
                   double blur_px);
  /// What the archival camera (a DSLR writing JPEG) does after the light reached the sensor, in
  /// place on its sRGB image: the lens's natural vignetting (cos^4 of the field angle), the
  /// picture style's S-shaped tone curve, and JPEG compression (quality kJpegQuality).
  static void archivalCamera(cv::Mat& srgb, const CameraModel& camera);
  static constexpr double kToneContrast = 0.15;  ///< S-curve v - c sin(2 pi v) / 2 pi on codes
  static constexpr int kJpegQuality = 92;         ///< a camera's "fine" JPEG
  /// CV_16UC1 depth in mm with noise, quantisation, min-Z holes and the left invalid band.
  cv::Mat depthImage(const cv::Mat& depth, const CameraModel& camera, bool left_band = true);

 private:
  std::mt19937 rng_;
  std::vector<float> gauss_;  ///< a table of N(0, 1) samples, read from a random offset
  std::vector<int16_t> noise_;  ///< gauss_ scaled by the colour noise sigma, in counts
  float noise_sigma_ = -1.0f;
};

}  // namespace rascal_sim
