#pragma once
// The background of one station: k-means clusters in HSV learnt from an image of the empty
// station (hue and saturation; value only rejects pixels too dark to trust), a tight hue band and
// a loose saturation band per cluster, where in the calibration view each cluster was seen, and
// the fixtures (what the empty station shows that is not background: chart, scale bar).
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/core/persistence.hpp>
#include <vector>

namespace rascal_perception {

struct BackgroundCluster {
  double hue = 0.0;         ///< circular mean, fraction of the hue circle [0, 1)
  double saturation = 0.0;  ///< mean S [0, 1]
  double value = 0.0;       ///< mean V [0, 1] (reported only)
  double fraction = 0.0;    ///< share of the trusted calibration pixels
  bool grey = false;        ///< saturation too low for its hue to mean anything: hue ignored
};

struct BackgroundOptions {
  int clusters = 3;                    ///< k, 1 .. 8
  double hue_tolerance = 0.15;         ///< half-width of the hue band (fraction of the circle)
  double saturation_tolerance = 0.35;  ///< half-width of the saturation band
  double min_value = 0.07;             ///< darker pixels: hue untrusted (never sherd, never fixture)
  double min_cluster_fraction = 0.02;  ///< smaller clusters are not background
  double grey_saturation = 0.12;       ///< clusters below this saturation ignore hue
  int prior_dilation_px = 12;          ///< where a cluster was seen, grown by this much
  unsigned seed = 1;                   ///< k-means seeding
};

class BackgroundModel {
 public:
  /// Learns the clusters, where they were seen, and the fixture mask from an RGB image of the
  /// empty station. Pixels under `ignore` (CV_8U, 255) are left out. Throws std::invalid_argument.
  void learn(const cv::Mat& rgb, const BackgroundOptions& options, const cv::Mat& ignore = cv::Mat());
  /// Re-learns the clusters only (light changed), keeping the seen-map and the fixtures.
  void refresh(const cv::Mat& rgb, const cv::Mat& ignore = cv::Mat());
  bool ready() const { return !lut_.empty(); }

  /// 255 where the HSV image (COLOR_RGB2HSV_FULL) is background. `allowed` (CV_8U, one bit per
  /// cluster, 0xFF = any) restricts which clusters count at each pixel; empty = any everywhere.
  void classify(const cv::Mat& hsv, const cv::Mat& allowed, cv::Mat& background) const;
  /// The same from the RGB image directly, through a table on RGB quantised to 6 bits per
  /// channel (the camera-rate path: no HSV image; hue and saturation of the bin's centre, the
  /// darkness test exact). Agrees with classify() except within one bin of a band's edge.
  void classifyRgb(const cv::Mat& rgb, const cv::Mat& allowed, cv::Mat& background) const;
  /// Bits of the clusters that match (hue, saturation) in 8-bit HSV_FULL units.
  uint8_t match(uint8_t hue, uint8_t saturation) const { return lut_[hue * 256 + saturation]; }

  const std::vector<BackgroundCluster>& clusters() const { return clusters_; }
  /// CV_8U, per calibration pixel the bits of the clusters seen nearby.
  const cv::Mat& seenMap() const { return seen_; }
  /// CV_8U 255 = fixture in the calibration image (not dilated).
  const cv::Mat& fixtureMask() const { return fixture_; }
  const BackgroundOptions& options() const { return options_; }

  /// The learnt model as entries of an open map in `fs` (clusters, options, seen-map, fixtures).
  void write(cv::FileStorage& fs) const;
  /// The model `write` wrote; the tables rebuilt from it. Throws std::invalid_argument when an
  /// entry is missing or out of range.
  void read(const cv::FileNode& node);

 private:
  void cluster(const cv::Mat& hsv, const cv::Mat& ignore);
  void buildLut();

  BackgroundOptions options_;
  std::vector<BackgroundCluster> clusters_;
  std::vector<uint8_t> lut_;  ///< 256 x 256 (hue, saturation) -> cluster bits
  std::vector<uint8_t> rgb_lut_;  ///< 64 x 64 x 64 (R, G, B >> 2) -> cluster bits
  cv::Mat seen_, fixture_;
};

}  // namespace rascal_perception
