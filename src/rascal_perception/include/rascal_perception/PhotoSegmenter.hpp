#pragma once
// Sherds and the scale bar in a photo (no depth, no calibration image): the cloth is modelled from
// the photo itself (a smooth local background in Lab that follows uneven light), or taken from a
// photo of the empty background; a sherd is what stands out from it in lightness or chromaticity
// (darker with the cloth's chromaticity is a shadow). The scale bar comes from findScaleBar.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_perception/ScaleBarFinder.hpp"
#include "rascal_perception/SherdSegmenter.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

/// Why a person should look at one sherd's result (bits of PhotoSherd::flags).
enum PhotoSherdFlag : unsigned {
  kProbablySeveral = 1u << 0,  ///< shape or size says it is probably several touching sherds
  kTouchesBorder = 1u << 1,    ///< the mask touches the image border: the sherd may be cut
  kLowContrast = 1u << 2,      ///< the outline is weak against the background (dark on dark)
  kNoScale = 1u << 3,          ///< no scale bar: sizes in mm unknown
};
/// "probably_several", "touches_border", "low_contrast", "no_scale" for the bits set.
std::vector<std::string> flagNames(unsigned flags);

struct PhotoSherd {
  Blob blob;
  double length_mm = 0.0, width_mm = 0.0, area_mm2 = 0.0;  ///< 0 without a scale bar
  cv::Vec3d colour;                                        ///< mean sRGB [0, 1]
  unsigned flags = 0;                                      ///< PhotoSherdFlag bits
};

struct PhotoResult {
  ScaleBar bar;
  std::vector<PhotoSherd> sherds;
  cv::Mat foreground;
  bool background_trusted = true;     ///< false: the background model is doubtful
  /// The cloth's outline (convex, full-resolution pixels) where the photo shows other surfaces
  /// around it (floor, table, chair): sherds lie on the cloth, so blobs outside are left out.
  /// Empty when the cloth fills the photo or an empty-background photo was given.
  std::vector<cv::Point> cloth_outline;
  std::vector<std::string> warnings;  ///< photo-wide doubts, one line each
};

class PhotoSegmenter {
 public:
  struct Options {
    int clusters = 6;             ///< k-means colours of the coarse photo that seed the surfaces
    double bar_length_cm = 10.0;  ///< passed to findScaleBar
    // Contrast to the local background, in units of the cloth's own spread (robust sigma of
    // L* and of the a*b* distance over background pixels): hysteresis between the two.
    double weak_contrast = 3.0;    ///< a pixel this far from the cloth may belong to a sherd ...
    double strong_contrast = 8.0;  ///< ... if its region holds a pixel this far
    double min_contrast_l = 3.0, min_contrast_ab = 2.0;  ///< floors of the two sigmas (Lab units)
    double low_contrast = 0.5;     ///< a sherd with less of its area above strong_contrast: kLowContrast
    double surface_fraction = 0.15;  ///< one connected piece of a colour this large (x photo) is a surface
    double min_clear = 0.05;       ///< a blob with less than this above strong_contrast is not a sherd
    // Sizes in mm: from the scale bar, or without it from the typical sherd taken as this long.
    double min_side_mm = 3.0, clean_radius_mm = 1.0;
    double typical_sherd_mm = 40.0;
    double max_side_mm = 300.0;      ///< with the bar: a blob longer than this is not a sherd
    double max_side_fraction = 0.4;  ///< without it: the same, x the photo's longer side
    double bar_margin_cm = 0.5;      ///< blobs on the bar's box grown by this are the bar
    double split_min_neck = 0.75;    ///< see PerceptionConfig::split_min_neck
  };
  explicit PhotoSegmenter(const Options& options) : options_(options) {}
  /// `background` empty: learn it from `rgb`; else an RGB photo of the empty background.
  PhotoResult segment(const cv::Mat& rgb, const cv::Mat& background = cv::Mat()) const;

 private:
  /// Per-pixel contrast to the cloth (CV_32F, in cloth sigmas); fills the trust fields of `r`.
  cv::Mat contrast(const cv::Mat& rgb, const cv::Mat& background, PhotoResult& r) const;
  /// Splits a blob in two along a straight dark crack from its deepest concavity when both
  /// halves are far more convex than the whole: sherds lying edge to edge, which have no neck
  /// for the distance transform and whose crack the closing has filled.
  void splitAtSeams(std::vector<Blob>& blobs, const cv::Mat& rgb) const;
  Options options_;
};

}  // namespace rascal_perception
