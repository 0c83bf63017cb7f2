#pragma once
// What the flat-shaded rendering lacks and a field photo has (scenario `lighting.realism`): the
// cloth's weave and the sherds' slip, paint and grit (textures sampled from the real photos in
// data/textures), each sherd's cast shadow on the cloth, and specular highlights on glazed
// surfaces. Applied to the wrist camera's frames, before the sensor's blur and noise.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rascal_sim/CameraModel.hpp"
#include "rascal_sim/Renderer.hpp"
#include "rascal_sim/Scenario.hpp"

namespace rascal_sim {

class SurfaceRealism {
 public:
  static constexpr double kTexturePxPerMetre = 2000.0;  ///< textures drawn at 20 px/cm (their photos: 14-30)
  static constexpr double kTableTop = 0.003;            ///< [m] cloth: fixture surfaces below this height

  /// Reads data/textures/cloth_*.png and sherd_*.png from `data_dir`; throws if there are none.
  void load(const std::string& data_dir);
  bool loaded() const { return !cloth_.empty() && !sherd_.empty(); }
  /// Modifies `colour` (sRGB, RGB order) of a rendering with its depth and label images.
  void apply(cv::Mat& colour, const RenderOutput& rendering, const CameraModel& camera,
             const Eigen::Isometry3d& world_T_camera, const Realism& realism) const;

 private:
  std::vector<cv::Mat> cloth_, sherd_;  ///< CV_32F relative luminance, mean about 1
};

}  // namespace rascal_sim
