#pragma once
// Everything the node drives: world physics, servos, gripper and grasp logic, scale, wrist and
// archival cameras, faults and sim time. No ROS communication.
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "rascal_sim/ArchivalCamera.hpp"
#include "rascal_sim/GripperModel.hpp"
#include "rascal_sim/Renderer.hpp"
#include "rascal_sim/ScaleSensor.hpp"
#include "rascal_sim/Scenario.hpp"
#include "rascal_sim/SensorEffects.hpp"
#include "rascal_sim/SurfaceRealism.hpp"
#include "rascal_sim/ServoModel.hpp"
#include "rascal_sim/World.hpp"
#include "rascal_workcell/GripperGeometry.hpp"

namespace rascal_sim {

/// Filled from config/rascal.yaml and the URDF by SimParameters::read (node, tests and tools).
struct SimulatorOptions {
  double physics_dt = 0.001;                         ///< [s]
  JointVector initial_joints{0.0, -1.80, 1.55, 0.0, 0.8, 0.0};  ///< sleep pose
  /// Finger travel from the URDF (GripperGeometry::fromPackageUrdf()); required: the Simulator
  /// refuses options without it.
  rascal_workcell::GripperGeometry gripper;
  double initial_finger = 0.0;                       ///< [m] left finger, within the gripper's limits
  bool wrist_camera = true;
  double wrist_rate = 30.0;                          ///< [Hz]
  CameraModel wrist_model = CameraModel::wristD435();
  int archival_width = 2000, archival_height = 1500;
};

struct WristFrame {
  double stamp = 0.0;
  cv::Mat rgb;        ///< CV_8UC3, RGB order
  cv::Mat depth_mm;   ///< CV_16UC1
  Eigen::Isometry3d world_T_camera = Eigen::Isometry3d::Identity();
  bool blurred = false;
};

/// Faults for tests (rascal_msgs/InjectFault): the codes of the service.
enum class Fault {
  kDropNextGrasp = 0,
  kScaleGlitch = 1,
  kCameraTimeout = 2,
  kScaleUnsettledTare = 3,  ///< the next tare catches the platform swinging (ScaleSensor)
  kScaleGlitchOnLoad = 4,   ///< a glitch from when the next sherd lands on the scale
};

class Simulator {
 public:
  static constexpr double kBlurSpeed = 0.05;    ///< [rad/s] timing.md
  static constexpr double kMaxPayload = 0.25;   ///< [kg] timing.md
  /// [m] per finger: a command this much more open than the last one is an open (1 mm opening).
  static constexpr double kReleaseStep = 0.0005;

  /// Throws std::invalid_argument when options.gripper is not set or initial_finger is outside it.
  Simulator(const WorldLayout& layout, const SimulatorOptions& options);
  /// Spawns the scenario's sherds and takes its lighting; remembered for reset(). A scenario whose
  /// station_offsets differ from the last one's rebuilds the world with the stations where it
  /// has them (the clock runs on; refused with std::runtime_error during an archival capture,
  /// std::invalid_argument naming an unknown station).
  void load(const Scenario& scenario);
  /// Re-spawns the last scenario and puts the arm back at its initial pose (time runs on).
  void reset();
  void step();
  double time() const { return world_->time(); }

  void commandArm(double start_time, const std::vector<TrajectoryPoint>& points,
                  const std::array<bool, kArmJoints>& mask);
  /// A target below the previous one closes (and may grasp what both fingers touch); one that
  /// opens (at least kReleaseStep above the previous target and not where the fingers already
  /// are, or fully open at gripper.finger_max, or beyond the fingers) lets a held sherd go at once.
  void commandGripper(double finger_position);
  /// Stops the fingers where they are; a held sherd stays held. While the fingers squeeze a
  /// sherd (held, or pressed by both fingers) after a close, a stop (this, or a command to where
  /// the fingers are) keeps the close target, as the PWM-mode servo keeps squeezing: when the
  /// sherd slips out, is dropped or leaves the fingers, they go on closing.
  void stopGripper();
  const JointVector& jointPositions() const { return servos_.positions(); }
  const JointVector& jointVelocities() const { return servos_.velocities(); }
  double fingerPosition() const { return gripper_.position(); }
  double fingerVelocity() const { return gripper_.velocity(); }
  bool armSettled() const { return servos_.settled(); }

  /// True once per new 10 Hz scale reading.
  bool takeScaleReading(ScaleReading& reading);
  void tareScale() { scale_.tare(); }

  bool wristFrameDue() const;
  /// Renders the wrist camera at the present time and schedules the next frame.
  WristFrame renderWristFrame();
  /// Drops the due frame unrendered (nobody is listening) and schedules the next one.
  void skipWristFrame();
  Eigen::Isometry3d wristCameraPose() const;
  const CameraModel& wristModel() const { return options_.wrist_model; }

  ArchivalCamera& archival() { return archival_; }
  /// Renders the archival view now (no noise budget for the shutter; used by the capture and tools),
  /// `exposure_ev` stops brighter (+) or darker (-) than the camera's configured exposure.
  cv::Mat renderArchival(double exposure_ev = 0.0);
  /// Starts a capture at `exposure_ev` (within +-kMaxExposureEv); false and `why` when refused.
  bool triggerCapture(std::string& why, double exposure_ev = 0.0);
  static constexpr double kMaxExposureEv = 3.0;

  /// The last close of the fingers: a grasp and how likely it was to slip (simulator's model),
  /// or a miss and what each finger touched on the way: for the node's log, so a run's drops
  /// and misses can be traced to their grasps. `count` grows by one a close.
  struct GraspRecord {
    int count = 0;
    std::string sherd;  ///< its name; a miss: the sherd nearest the fingers' middle
    double time = 0.0;
    double off_centre = 0.0;  ///< of half the sherd's length, 0..1
    double along = 0.0;       ///< |cos| of the closing direction to the outline's major axis
    double elongation = 0.0;  ///< 1 - width / length of the outline
    double slip_chance = 0.0;
    bool miss = false;
    std::string left, right;     ///< a miss: the sherd each finger last touched ("" none)
    double finger = 0.0;         ///< a miss: where the fingers stopped [m, each from the middle]
    double ee_z = 0.0;           ///< a miss: ee_gripper_link's height [m]
    double low = 0.0, high = 0.0;  ///< a miss: the nearest sherd's box, lowest and highest [m]
    /// One line for a log: "grasp of sherd_04 at t=101.29 s: ... slip chance 0.352", or
    /// "miss at t=...: fingers stopped at 15.0 mm, left touched sherd_03, right nothing; ...".
    /// Heights are base_link z, not above the station the sherd lies on (the scale's platform top
    /// is 25 mm up in config/rascal.yaml).
    std::string describe() const;
  };
  const GraspRecord& lastGrasp() const { return last_grasp_; }

  /// The arm coming into contact with a sherd it does not hold while no close is under way (a
  /// finger coming down on a neighbour, the gripper brushing the heap on its way): for the
  /// node's log, so that a sherd knocked off the mat is traced to the move that knocked it. A
  /// contact starts a bump when that sherd was not touched for kBumpGap.
  struct BumpRecord {
    double time = 0.0;
    std::string sherd, link;  ///< the sherd touched; the arm link whose box touched it
    Eigen::Vector3d ee = Eigen::Vector3d::Zero();      ///< ee_gripper_link [m]
    Eigen::Vector2d at = Eigen::Vector2d::Zero();      ///< the sherd's centre (x, y) [m]
    double low = 0.0, high = 0.0;  ///< the sherd's box, lowest and highest z [m]
    /// [m] where they touched, in ee_gripper_link's frame (pointing down: x down, y the fingers'
    /// closing direction): which face of the finger or hand met the sherd
    Eigen::Vector3d contact = Eigen::Vector3d::Zero();
    /// "bump at t=124.95 s: left_finger_link on sherd_21 at (0.284, 0.199) m, its box from z
    /// 12.1 to 25.3 mm; ee_gripper_link at (0.229, 0.218, 0.061) m; touching at (-4.0, 27.5,
    /// 3.1) mm in its frame"
    std::string describe() const;
  };
  static constexpr double kBumpGap = 0.25;  ///< [s]
  /// The bumps since the last call, oldest first (the last kMaxBumps kept).
  std::vector<BumpRecord> takeBumps();
  /// The node's log lines since the last call ("grasp of …"/"miss at …" for a close not yet
  /// given, then the bumps, takeBumps): what a bench traces a run's drops, misses and pushes by.
  std::vector<std::string> takeLogLines();
  static constexpr size_t kMaxBumps = 100;

  bool injectFault(int fault, double duration, std::string& message);
  std::vector<SherdState> groundTruth() const;
  World& world() { return *world_; }
  const Scenario& scenario() const { return scenario_; }
  const SimulatorOptions& options() const { return options_; }

 private:
  /// The world (and the archival camera on its stand) rebuilt with the configured stations moved
  /// by `offsets`.
  void moveStations(const std::map<std::string, StationOffset>& offsets);
  void updateGrasp();
  /// A close is under way and a sherd is held or pressed by both fingers.
  bool squeezing() const;
  /// Lets the held sherd go because the fingers open: it falls out of them under physics.
  void releaseByOpening();

  WorldLayout layout_;  ///< as configured; the world has the stations where they really stand
  SimulatorOptions options_;
  std::unique_ptr<World> world_;  ///< rebuilt when a scenario moves the stations
  ServoModel servos_;
  GripperModel gripper_;
  ScaleSensor scale_;
  ArchivalCamera archival_;
  Renderer renderer_;
  static constexpr unsigned kSensorSeed = 11;  ///< the camera noise starts here at every load()
  SensorEffects effects_;
  SurfaceRealism realism_;  ///< loaded with the first scenario that asks for it
  Scenario scenario_;
  std::mt19937 rng_;
  double next_wrist_frame_ = 0.0;
  bool scale_fresh_ = false;
  bool drop_next_grasp_ = false;
  double capture_exposure_ev_ = 0.0;  ///< of the capture under way
  double camera_fault_until_ = -1.0;
  // grasp bookkeeping
  double grasp_z_ = 0.0;
  bool close_armed_ = false;     // a close was commanded since the last open: may grasp
  bool open_requested_ = false;  // an open was commanded: the held sherd goes
  bool slip_armed_ = false;
  double slip_delay_ = 0.0, slip_lifted_since_ = -1.0;
  GraspRecord last_grasp_;
  int close_left_ = -1, close_right_ = -1;  // what each finger touched during this close
  bool close_recorded_ = false;             // this close's grasp or miss is in last_grasp_
  void recordMiss();
  void recordBumps();
  std::map<int, double> last_touch_;  // each sherd's last contact with the arm [s]
  std::vector<BumpRecord> bumps_;
  int grasps_logged_ = 0;  // last_grasp_.count given by takeLogLines
  RenderOutput scratch_;
  std::vector<RenderItem> items_;
};

}  // namespace rascal_sim
