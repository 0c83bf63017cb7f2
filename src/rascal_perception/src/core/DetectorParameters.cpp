#include "rascal_perception/DetectorParameters.hpp"

namespace rascal_perception {

DetectorParameters DetectorParameters::read(const rascal_workcell::Parameters& p,
                                            const rascal_workcell::GripperGeometry& gripper) {
  DetectorParameters d;
  PerceptionConfig& c = d.config;
  c.background_clusters = p.integer("perception.background_clusters");
  c.hue_tolerance = p.number("perception.hue_tolerance");
  c.saturation_tolerance = p.number("perception.saturation_tolerance");
  c.min_value = p.number("perception.min_value");
  c.fixture_dilation = p.number("perception.fixture_dilation");
  c.min_sherd_size = p.number("perception.min_sherd_size");
  c.max_sherd_size = p.number("perception.max_sherd_size");
  c.border_margin = p.integer("perception.border_margin");
  c.depth_min = p.number("perception.depth_min");
  c.depth_max = p.number("perception.depth_max");
  c.min_sherd_height = p.number("perception.min_sherd_height");
  c.split_min_neck = p.number("perception.split_min_neck");
  c.grasp_height_fraction = p.number("perception.grasp_height_fraction");
  c.grasp_tip_clearance = p.number("perception.grasp_tip_clearance");
  c.grasp_margin = p.number("arm.grasp_margin");
  c.held_margin = p.number("arm.gripper.held_margin");
  c.gripper = gripper.withPads(p.number("arm.gripper.fingertip_pads"));
  d.frame_wait = p.number("perception.frame_wait");
  d.refresh_period = p.number("perception.refresh_period");
  d.workcell = rascal_workcell::Workcell::fromParameters(p);
  p.checkAllRead();
  return d;
}

}  // namespace rascal_perception
