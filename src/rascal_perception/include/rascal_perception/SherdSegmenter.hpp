#pragma once
// Colour image -> sherd blobs: background and fixtures removed, holes filled, blobs cut by the
// image border rejected, touching sherds separated (distance transform + watershed).
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_perception/BackgroundModel.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

struct SegmentationOptions {
  double min_side_px = 10.0;     ///< blobs with a shorter oriented-box side are noise
  double max_side_px = 1e9;      ///< blobs with a longer side are not one sherd
  int border_margin = 3;         ///< [px]
  double split_min_neck = 0.75;  ///< see PerceptionConfig
  bool split = true;
  /// false: blobs are returned whatever their size and however near the border, for the caller
  /// to cut apart first (StackSplitter: a heap is one blob larger than any sherd, often cut by
  /// the image border, with whole sherds in it) and to check each part with `accept`.
  bool check = true;
};

struct SegmentationStats {
  int rejected_border = 0, rejected_size = 0, splits = 0;
};

/// What the border and size checks say of one blob.
enum class BlobCheck { kAccepted, kCutByBorder, kTooSmall, kTooLarge };

class SherdSegmenter {
 public:
  /// Foreground = not background (per `allowed`, see BackgroundModel::classify) and not `fixture`,
  /// or-ed with `raised` (CV_8U 255: pixels the depth shows above the surface; may be empty).
  /// Returns the blobs; `foreground` receives the cleaned mask.
  std::vector<Blob> segment(const cv::Mat& rgb, const BackgroundModel& model, const cv::Mat& allowed,
                            const cv::Mat& fixture, const cv::Mat& raised, const SegmentationOptions& options,
                            cv::Mat& foreground, SegmentationStats* stats = nullptr) const;
  /// Blobs of a binary mask (no colour model): contours, border and size checks, splitting.
  std::vector<Blob> blobs(const cv::Mat& mask, const SegmentationOptions& options,
                          SegmentationStats* stats = nullptr) const;
  /// The border and size checks of one blob.
  static BlobCheck check(const Blob& blob, const cv::Size& image, const SegmentationOptions& options);
  /// check() == kAccepted; a failure is counted in `stats`.
  static bool accept(const Blob& blob, const cv::Size& image, const SegmentationOptions& options,
                     SegmentationStats& stats);
  /// Splits one filled blob mask at its necks; returns 1 mask if it is one sherd.
  std::vector<cv::Mat> split(const cv::Mat& mask, double min_neck, double min_peak_px) const;
  /// The largest outer contour of `part` (CV_8U) as a blob; `offset` = image position of part(0, 0).
  /// Empty contour if `part` is empty.
  static Blob blobOf(const cv::Mat& part, const cv::Point& offset);

 private:
  mutable cv::Mat background_;
};

}  // namespace rascal_perception
