#!/usr/bin/env bash
# The main job in simulation: a master, the simulator with the config's 10-sherd scenario, the
# arm controller and the detector (each started with rosrun, as on the field rig), the local
# PostgreSQL that setup.sh started; one batch, then the per-sherd table and the report's path.
# Run through `make demo`, which does the set-up first.
set -eo pipefail
cd "$(dirname "$0")/.."
# shellcheck disable=SC1091
source devel/setup.bash
context=${RASCAL_DEMO_CONTEXT:-DEMO-$(date +%Y%m%d-%H%M%S)}

# What the demo needs; say plainly what is not there yet rather than pretend.
missing=()
for node in rascal_sim/sim rascal_control/arm_controller rascal_perception/sherd_detector; do
  [ -x "devel/lib/$node" ] || missing+=("$node")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "demo: not built: ${missing[*]}; nothing was run."
  exit 1
fi

rosrun rascal_tasks rascal db migrate
echo "demo: context $context; simulator, arm_controller and sherd_detector start with rosrun"
/usr/bin/python3 -m rascal_tasks.sim_rig -- bash -c "
  rosrun rascal_tasks rascal run --context '$context' &&
  rosrun rascal_tasks rascal report --context '$context'"
