#pragma once
// The whole pipeline per station: calibrate a background model on the empty station, then detect
// sherds (segment -> separate -> measure -> grasp -> score). The calibration view is carried to a
// later camera pose through the homography of the station plane, so the survey may move.
#include <map>
#include <string>
#include <vector>

#include "rascal_perception/BackgroundModel.hpp"
#include "rascal_perception/GraspPlanner.hpp"
#include "rascal_perception/SherdMeasurer.hpp"
#include "rascal_perception/SherdSegmenter.hpp"
#include "rascal_perception/StackSplitter.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

struct CalibrationResult {
  bool success = false;
  std::string message;
  int clusters = 0;
  double fixture_fraction = 0.0;  ///< share of the image masked as fixture (after dilation)
};

class SherdDetector {
 public:
  /// A sherd rising more than its width seen from above, and at least this many
  /// perception.min_sherd_size, above what it rests on is not offered but left, standing on its
  /// edge (Leftover::on_edge), for the task layer to push over: a sherd set down hanging from the
  /// fingers stood 39 mm tall on the pan, 24 mm wide from above, and was offered, missed and
  /// recorded lost (heap seed 45). A short thick chip is still offered.
  static constexpr double kStandingHeight = 2.0;
  /// Throws std::invalid_argument when config.gripper is unset (see GraspPlanner).
  explicit SherdDetector(const PerceptionConfig& config);
  /// Learns `station`'s background from an image of it empty. `depth_mm` may be empty.
  CalibrationResult calibrate(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                              const CameraView& view, double surface_z);
  /// Re-learns the station's colours from a frame with sherds in it (the sherds left out).
  CalibrationResult refresh(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                            const CameraView& view, double surface_z);
  /// Sherds in base_link, best score first (ties in segmentation order: deterministic for a given
  /// frame); the task layer chooses which to pick. `depth_mm` may be empty (no heights).
  DetectionResult detect(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                         const CameraView& view, double surface_z);
  /// Segmentation only: the blobs and the foreground mask (for benches and the annotated image).
  /// `check` false: blobs of any size and at the border too (detect checks the parts after
  /// cutting stacks apart).
  std::vector<Blob> segment(const std::string& station, const cv::Mat& rgb, const cv::Mat& depth_mm,
                            const CameraView& view, double surface_z, cv::Mat& foreground,
                            SegmentationStats* stats = nullptr, bool check = true);
  /// The segmentation's options for a view of a station surface (sizes in pixels there).
  SegmentationOptions segmentationOptions(const CameraView& view, double surface_z) const;
  bool calibrated(const std::string& station) const { return stations_.count(station) > 0; }
  const BackgroundModel* model(const std::string& station) const;
  const PerceptionConfig& config() const { return config_; }
  /// The station's background (model, calibration view, surface, fixtures) as entries of an open
  /// map in `fs`; false when the station has none.
  bool write(const std::string& station, cv::FileStorage& fs) const;
  /// `station`'s background from what write() wrote. Throws std::invalid_argument.
  void read(const std::string& station, const cv::FileNode& node);

 private:
  struct Station {
    BackgroundModel model;
    CameraView view;
    double surface_z = 0.0;
    cv::Mat fixture;  ///< dilated, calibration view
  };
  /// The station's seen-map and fixture mask in the present view.
  void warpPriors(const Station& s, const CameraView& view, double surface_z, cv::Mat& allowed, cv::Mat& fixture) const;
  /// 255 where the depth is more than min_sherd_height above the surface.
  cv::Mat raised(const cv::Mat& depth_mm, const CameraView& view, double surface_z);
  /// [px per m] at the station surface along the optical axis.
  double pixelsPerMetre(const CameraView& view, double surface_z) const;

  PerceptionConfig config_;
  std::map<std::string, Station> stations_;
  SherdSegmenter segmenter_;
  StackSplitter stacks_;
  SherdMeasurer measurer_;
  GraspPlanner planner_;
  cv::Mat ray_z_;
  Eigen::Matrix3d ray_z_rotation_ = Eigen::Matrix3d::Zero();
  /// per pixel the deepest reading [mm] that is still min_sherd_height above the surface, for
  /// the camera height it was made for (a comparison per pixel instead of a ray per pixel)
  cv::Mat raised_below_;
  float raised_cam_z_ = -1.0f;
  bool ray_z_rotation_changed_ = true;
  cv::Mat allowed_, fixture_, usable_;
};

}  // namespace rascal_perception
