#pragma once
// A top-down grasp per sherd and a score; the gripper's fingers close across the minor axis.
//
// ee_gripper_link target: the sherd's centre, orientation R = Rz(yaw) * Ry(pi/2) (x down, fingers
// closing along R*y = across the major axis), at
//   z = surface + max(grasp_height_fraction * height, grasp_tip_clearance) + gripper.fingertip_offset,
// i.e. the fingertips close at 60 % of the measured top height but never lower than 2.5 mm above
// the station surface; opening = width + grasp_margin clamped to the gripper's opening limits
// (the URDF's finger limits: 30 .. 74 mm on the wx250s).
//
// With the height map (GraspContext) the fingers' footprints are checked too: each finger, 20 mm
// wide and 8 mm thick, beside the sherd at the opening, must close above what lies there (a
// neighbour in a heap). The minor axis is tried first, then the offers of kOffers, least
// holdCost first: turned by 15, 20, 25, 30, 45 and 90 degrees (the opening follows the outline's
// extent across each: the least turn that clears a neighbour, or whose chord a sherd too narrow
// to hold across can be held by), moved along the sherd by a quarter and by 45 % of its
// half-length (the opening follows the outline's extent within the fingers' width there), and
// turned 15 degrees and moved by a quarter; an elongated sherd is moved before it is turned far,
// a round one turned. The first clear one whose chord the fingers can hold (holdableChord) is
// taken (grasp_clear unless its chord is much longer than the minor axis's, kMaxChordRatio,
// while the minor axis itself could be held),
// else the clearest holdable one, else the clearest (grasp_clear false).
#include <opencv2/core.hpp>
#include <vector>

#include "rascal_perception/SherdMeasurer.hpp"
#include "rascal_perception/Types.hpp"

namespace rascal_perception {

/// What the planner may look at around a sherd: the height map above the table plane
/// (StackSplitter::heightMap), the view it was taken from and the sherd's own pixels.
struct GraspContext {
  const cv::Mat* height = nullptr;
  const CameraView* view = nullptr;
  const Blob* own = nullptr;
};

class GraspPlanner {
 public:
  static constexpr double kFingerWidth = 0.020;  ///< [m] gap that lets a finger in (score saturates)
  /// [m] a finger's thickness along the closing direction (the simulator's finger box; the
  /// scenario generator keeps this and the grasp margin between sherds)
  static constexpr double kFingerThickness = 0.008;
  /// [m] a fingertip this far above what lies under its footprint is clear
  static constexpr double kFingerClearance = 0.0005;
  /// Samples (2 mm apart, 4 mm^2 each) of a finger's footprint higher than its tip that block it.
  /// The 90th percentile of the footprint's ~55 was taken before: a neighbour's corner under
  /// less than a tenth of it (~20 mm^2) did not block the finger, which came down on it
  /// (heap_25_offcentre seed 73, a neighbour pushed off the mat; on generated heaps 5 of 67
  /// grasps offered clear came down on a neighbour by the simulator's truth, 1 of 65 with 3).
  static constexpr size_t kBlockingSamples = 3;
  /// A grasp turned off the minor axis closes on a longer chord, nearer the sherd's narrow ends
  /// and with its length as a lever about the contacts: one whose chord is longer than this times
  /// the minor-axis chord is not offered as clear (grasp_clear false: an elongated sherd turned
  /// 45 or 90 degrees to miss a neighbour slips, so it waits until its neighbours are gone). A
  /// near-round sherd turns freely.
  static constexpr double kMaxChordRatio = 1.25;
  /// One grasp to try: turned off the minor axis, and moved along the sherd's major axis (a
  /// fraction of its half-length). Moved, the fingers still close across the narrow way (on a
  /// chord no longer than the middle's, for a sherd narrowing to its ends), with the sherd's
  /// mass off the grasp by the shift: a neighbour beside the sherd's middle is missed that way,
  /// where a turn of 30 or 45 degrees would close near its ends (heap_20 seed 58: three sherds of 20 turned 40-70 degrees, the model's
  /// slip chance 0.26-0.32 each). Tried in the order of holdCost, least first.
  struct Offer {
    double turn_deg, shift;
  };
  static constexpr Offer kOffers[] = {{0.0, 0.0},    {15.0, 0.0},   {-15.0, 0.0},   {0.0, 0.25},   {0.0, -0.25},
                                      {15.0, 0.25},  {15.0, -0.25}, {-15.0, 0.25},  {-15.0, -0.25}, {20.0, 0.0},
                                      {-20.0, 0.0},  {25.0, 0.0},   {-25.0, 0.0},   {30.0, 0.0},   {-30.0, 0.0},
                                      {0.0, 0.45},   {0.0, -0.45},  {45.0, 0.0},    {-45.0, 0.0},  {90.0, 0.0}};
  /// How much worse an offer holds than the minor axis through the centre, for a sherd of
  /// `elongation` (1 - width / length): the shift squared (the mass's lever about the line the
  /// fingers close on) plus the sine of the turn squared (how far along the length they close),
  /// the latter in full from kElongated and less on a rounder sherd, which turns freely. Not a
  /// measured figure: the shape of the simulator's slip model (rascal_sim::SlipModel), whose
  /// causes are the ones that hold for a real sherd. Ties keep kOffers' order.
  static double holdCost(const Offer& offer, double elongation);
  static constexpr double kElongated = 0.4;

  /// Throws std::invalid_argument when config.gripper has no finger limits (not read from a URDF).
  explicit GraspPlanner(const PerceptionConfig& config);
  /// Fills grasp and grasp_width of one sherd (and finger_clearance, grasp_clear with `context`).
  void plan(SherdDetection& sherd, const GraspContext* context = nullptr) const;
  /// Fills clearance (gap to the nearest other outline) and score of every sherd.
  void score(std::vector<SherdDetection>& sherds) const;
  double minOpening() const { return config_.gripper.minOpening(); }  ///< [m]
  double maxOpening() const { return config_.gripper.maxOpening(); }  ///< [m]
  /// [m] a sherd may be this much narrower at the fingertips' height than its outline (the
  /// depth camera's millimetre, a tapering edge)
  static constexpr double kChordAllowance = 0.001;
  /// [m] the least chord across the fingers that they can be told to hold: closed on anything
  /// narrower they stop within held_margin of shut, which the gripper reads as empty (the
  /// wx250s's fingers close to 30 mm apart).
  double holdableChord() const { return minOpening() + config_.held_margin + kChordAllowance; }

 private:
  /// [m] the fingertip height for a grasp along `yaw` across `chord` about `centre`: `tip` (the
  /// rule of the header), lowered where the sherd's own top near either end of the chord lies
  /// lower (a sherd leaning on another: the rule's height over the one it rests on closes above
  /// its middle, or meets only its raised end); never under grasp_tip_clearance, and not for a
  /// sherd standing steeply (kSteepRise).
  double tipAtChordEnds(double yaw, double chord, const Eigen::Vector2d& centre, double surface, double tip,
                        double own, const GraspContext& context) const;
  /// [m] how far in from each end of the chord the sherd's top is read
  static constexpr double kEndBand = 0.006;
  /// A sherd whose top rises more than this times the chord from one end to the other (steeper
  /// than 45 degrees) keeps the rule's height: pinched low it hangs from the fingers by its lower
  /// edge, and was set down standing on the pan (heap seed 45) or slipped (seed 46).
  static constexpr double kSteepRise = 1.0;
  /// [m] fingertip height above the plane minus what lies under the fingers' footprints.
  double fingerClearance(double yaw, double opening, const Eigen::Vector2d& centre, double surface, double tip,
                         const GraspContext& context) const;
  /// [m] the least height of the hand above the fingers (the gripper, its bar, the wrist camera:
  /// config.gripper.hand, from the URDF) over what lies under it, at the grasp and turned by pi
  /// (the task layer turns the wrist either way: the fingers are alike, the camera is not). In
  /// heaps a neighbour tilted up or standing on its edge, beyond the fingers' reach, met the bar
  /// 32 mm over the fingertips or the camera 55 mm over them (heap_25_offcentre seed 95: the
  /// camera on a sherd standing 82 mm tall, pushed off the mat).
  double handClearance(double yaw, const Eigen::Vector2d& centre, double surface, double tip,
                       const GraspContext& context) const;
  /// [m] samples of the hand's footprints this far apart (its boxes are 20-100 mm)
  static constexpr double kHandStep = 0.004;
  PerceptionConfig config_;
};

}  // namespace rascal_perception
