// The gripper as the controller sees it: where a command sends the fingers, how long the stroke
// is commanded to take, when a command is done (finger at the target, or stalled on an object),
// and THE holding rule, the one the close result, the published gripper state and so the task
// layer all use. Fed with plain finger samples (the node feeds it /joint_states). No ROS.
#pragma once

#include <deque>
#include <limits>
#include <string>

#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_control {

// The fingers in one /joint_states message.
struct FingerSample {
  double t = 0.0;         // [s] the driver's stamp (arrival time if it has none)
  double position = 0.0;  // [m] left_finger from the centreline
  double velocity = std::numeric_limits<double>::quiet_NaN();  // [m/s] left_finger; NaN: none sent
  double opening = 0.0;   // [m] between the finger joints (left - right, or 2 x left); in the
                          // monitor's history, between the fingers (less the pads: addSample)
};

class GripperMonitor {
 public:
  // rascal_msgs/Gripper's command codes.
  static constexpr int kOpen = 0;
  static constexpr int kClose = 1;
  static constexpr int kWidth = 2;

  struct Settings {
    double stroke_time = 0.5;    // [s] commanded time of a full stroke
    double timeout = 3.0;        // [s] fingers still moving after this long: TIMEOUT
    double held_margin = 0.002;  // [m] of opening: a close stopped this much wider than closed holds
  };
  static constexpr double kFingerReached = 0.0005;   // [m] finger this close to its target: done
  static constexpr double kFingerStall = 0.0001;     // [m] finger motion over kStallWindow = stopped
  static constexpr double kStallWindow = 0.1;        // [s]
  static constexpr double kFingerStopped = 1e-4;     // [m/s] reported finger speed = stopped
  static constexpr std::size_t kStoppedSamples = 3;  // consecutive samples below kFingerStopped
  static constexpr double kHistory = 1.0;            // [s] of samples kept

  struct Target {
    bool valid = false;
    double finger = 0.0;  // [m] left finger position to command
    std::string reason;   // why not, when invalid
  };
  enum class Status { Moving, Done, Timeout };
  struct Decision {
    Status status = Status::Moving;
    bool holding = false;  // the holding rule, once the command is over
    std::string reason;    // "opening 41.2 mm, holding an object" or why it timed out
    bool done() const { return status != Status::Moving; }
  };

  GripperMonitor(const rascal_workcell::GripperGeometry& gripper, const Settings& settings);

  // Where `command` sends the left finger: OPEN to `width` (0 = fully open), CLOSE fully, WIDTH
  // to `width` [m of opening]. Invalid for another command or a width outside the URDF's limits.
  Target target(int command, double width) const;
  // [s] commanded time of a stroke of the left finger from `from` to `to`: its share of a full one.
  double strokeTime(double from, double to) const;

  // Every /joint_states message once the finger is known. A stamp earlier than the last one (the
  // driver restarted, and with it its finger command) clears the history and forgets the command.
  void addSample(const FingerSample& sample);
  bool hasSample() const { return !history_.empty(); }
  const FingerSample& latest() const { return history_.back(); }  // only when hasSample()

  // A command to `finger` [m] has been sent; the latest sample is where it starts from.
  void start(double finger);
  // Whether the command is over, `elapsed` [s] of ROS time and `wall` [s] of wall time after it
  // was sent. Done when the finger is within kFingerReached of the target or has stalled (after it
  // has moved: the last kStoppedSamples velocities below kFingerStopped, or it moved less than
  // kFingerStall in the last kStallWindow of stamps; before it has moved: still for a full
  // stroke's time plus the window). Timeout after settings.timeout in both times.
  Decision update(double elapsed, double wall);
  // The command was cancelled and the fingers told to stop where they are.
  void cancel();

  // THE holding rule, on the latest sample: the last command was closing and is over (the fingers
  // stopped) with the left finger more than held_margin/2 wider than its target. Before any
  // command (a controller restart): fingers between closed + held_margin/2 and fully open -
  // held_margin (neither shut on nothing nor open) count as holding.
  bool holding() const;

  const rascal_workcell::GripperGeometry& geometry() const { return gripper_; }

 private:
  bool stalled(double elapsed, double wall) const;

  rascal_workcell::GripperGeometry gripper_;
  Settings settings_;
  std::deque<FingerSample> history_;
  // The last command.
  bool known_ = false;    // one has been sent (since this controller or the driver started)
  bool closing_ = false;  // its target was narrower than where the finger started
  bool over_ = false;     // done, timed out or cancelled
  double target_ = 0.0;   // [m] left finger
  double from_ = 0.0;     // [m] left finger when it was sent
};

}  // namespace rascal_control
