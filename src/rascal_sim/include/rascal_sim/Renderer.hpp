#pragma once
// Software rasteriser with a z-buffer: flat-shaded triangles, pinhole projection, near-plane
// clipping. Produces an 8-bit sRGB image lit by a global linear gain, metric depth (z along the
// optical axis) and a label image.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_sim/CameraModel.hpp"
#include "rascal_sim/Mesh.hpp"

namespace rascal_sim {

struct RenderItem {
  const Mesh* mesh = nullptr;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< mesh frame in the world
  int id = 0;                                              ///< written to the label image
};

struct RenderOutput {
  cv::Mat colour;    ///< CV_8UC3 sRGB (RGB order), 0 where nothing was drawn
  cv::Mat depth;     ///< CV_32FC1 [m], 0 where nothing was drawn
  cv::Mat label;     ///< CV_16UC1 RenderItem::id of the visible surface, 0 = none
};

class Renderer {
 public:
  /// `world_T_camera` is the optical frame in the world.
  /// `gain` multiplies the linear radiance of every surface (brightness x colour temperature).
  void render(const std::vector<RenderItem>& items, const CameraModel& camera,
              const Eigen::Isometry3d& world_T_camera, RenderOutput& out,
              const Eigen::Vector3f& gain = Eigen::Vector3f::Ones()) const;
  /// 8-bit sRGB of a linear value (clamped to [0, 1]).
  static uint8_t encodeSrgb(float linear);
  /// Linear value of an 8-bit sRGB code.
  static float decodeSrgb(uint8_t code);

 private:
  mutable std::vector<Eigen::Vector3d> cam_vertices_;
};

}  // namespace rascal_sim
