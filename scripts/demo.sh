#!/usr/bin/env bash
# The main job in simulation: a master, the simulator with the config's scenario, every node
# started with rosrun (as on the field rig), a local PostgreSQL, one batch, then the per-sherd
# table and the report's path. Run through `make demo` (which does the set-up first).
set -eo pipefail
cd "$(dirname "$0")/.."
ws=$PWD
# shellcheck disable=SC1091
source devel/setup.bash
context=${RASCAL_DEMO_CONTEXT:-DEMO-$(date +%Y%m%d-%H%M%S)}

# What the demo needs; say plainly what is not there yet rather than pretend.
missing=()
need() { rospack find "$1" >/dev/null 2>&1 && [ -n "$(catkin_find --without-underlays --libexec "$1" "$2" 2>/dev/null || find "$(rospack find "$1")" -name "$2" -perm -u+x 2>/dev/null | head -1)" ] || missing+=("$1/$2"); }
need rascal_sim sim
need rascal_control arm_controller
need rascal_perception sherd_detector
need rascal_tasks rascal
if [ ${#missing[@]} -gt 0 ]; then
  echo "demo: not built yet: ${missing[*]}"
  echo "demo: the full batch needs the simulator, arm controller, detector and task node;"
  echo "      nothing was run. (make test runs what exists.)"
  exit 1
fi

port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_HOSTNAME=127.0.0.1
export ROS_LOG_DIR=$ws/var/log/demo-$context ROS_HOME=$ws/var/ros
mkdir -p "$ROS_LOG_DIR"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; sleep 1;
            for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null || true; done; }
trap cleanup EXIT
roscore -p "$port" >"$ROS_LOG_DIR/roscore.log" 2>&1 & pids+=($!)
until rosparam get /run_id >/dev/null 2>&1; do sleep 0.2; done
rosparam load config/rascal.yaml
rosparam set /use_sim_time true
rosparam set /robot_description -t src/rascal_description/urdf/wx250s.urdf
rosrun rascal_sim sim >"$ROS_LOG_DIR/sim.log" 2>&1 & pids+=($!)
rosrun rascal_control arm_controller >"$ROS_LOG_DIR/arm_controller.log" 2>&1 & pids+=($!)
rosrun rascal_perception sherd_detector >"$ROS_LOG_DIR/sherd_detector.log" 2>&1 & pids+=($!)
rosrun rascal_tasks rascal run --context "$context"
rosrun rascal_tasks rascal report --context "$context"
