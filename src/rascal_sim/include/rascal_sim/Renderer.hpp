#pragma once
// Software rasteriser with a z-buffer: flat-shaded triangles, pinhole projection, near-plane
// clipping. Produces linear-RGB radiance and metric depth (z along the optical axis).
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
  cv::Mat radiance;  ///< CV_32FC3 linear RGB, 0 where nothing was drawn
  cv::Mat depth;     ///< CV_32FC1 [m], 0 where nothing was drawn
  cv::Mat label;     ///< CV_16UC1 RenderItem::id of the visible surface, 0 = none
};

class Renderer {
 public:
  /// `world_T_camera` is the optical frame in the world.
  void render(const std::vector<RenderItem>& items, const CameraModel& camera,
              const Eigen::Isometry3d& world_T_camera, RenderOutput& out) const;

 private:
  mutable std::vector<Eigen::Vector3d> cam_vertices_;
};

}  // namespace rascal_sim
