#pragma once
// Sherds and the scale bar in a photo (no depth, no calibration image): the background is learnt
// from the photo itself (`--background auto`: k-means in HSV with value, the largest cluster and
// those near it are background), or from a photo of the empty background. The scale bar is the
// most rectangular, unsaturated blob of about 5 : 1; it gives the pixels per centimetre.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_perception/SherdSegmenter.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

struct ScaleBar {
  bool found = false;
  cv::RotatedRect box;      ///< in image pixels
  double px_per_cm = 0.0;   ///< long side / bar length
};

struct PhotoSherd {
  Blob blob;
  double length_mm = 0.0, width_mm = 0.0, area_mm2 = 0.0;  ///< 0 without a scale bar
  cv::Vec3d colour;                                        ///< mean sRGB [0, 1]
};

struct PhotoResult {
  ScaleBar bar;
  std::vector<PhotoSherd> sherds;
  cv::Mat foreground;
};

class PhotoSegmenter {
 public:
  struct Options {
    int clusters = 6;
    double background_distance = 0.15;  ///< clusters this close to the largest one are background too
    double bar_length_cm = 10.0;
    double bar_aspect_min = 3.5, bar_aspect_max = 7.0;
    double min_side_fraction = 0.012;   ///< blobs with a shorter side (x image width) are noise
    double max_side_fraction = 0.35;    ///< blobs with a longer side (x image width) are background
    double split_min_neck = 0.75;       ///< see PerceptionConfig::split_min_neck
    unsigned seed = 1;
  };
  explicit PhotoSegmenter(const Options& options) : options_(options) {}
  /// `background` empty: learn it from `rgb`; else an RGB photo of the empty background.
  PhotoResult segment(const cv::Mat& rgb, const cv::Mat& background = cv::Mat()) const;
  /// The scale bar among `blobs` (removed from them when found).
  ScaleBar findBar(const cv::Mat& rgb, std::vector<Blob>& blobs) const;

 private:
  cv::Mat foreground(const cv::Mat& rgb, const cv::Mat& background) const;
  /// Splits a blob in two along a straight dark crack from its deepest concavity when both
  /// halves are far more convex than the whole: sherds lying edge to edge, which have no neck
  /// for the distance transform and whose crack the closing has filled.
  void splitAtSeams(std::vector<Blob>& blobs, const cv::Mat& rgb) const;
  /// Joins a much smaller blob to a larger one it (nearly) touches.
  void mergeFragments(std::vector<Blob>& blobs, const cv::Size& size) const;
  Options options_;
};

}  // namespace rascal_perception
