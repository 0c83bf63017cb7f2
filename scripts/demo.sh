#!/usr/bin/env bash
# The main job in simulation: a master, the simulator with the config's 10-sherd scenario, the
# arm controller and the detector (each started with rosrun, as on the field rig), the local
# PostgreSQL that setup.sh started; one batch, then the per-sherd table and the report's path.
# Run through `make demo`, which does the set-up first. `make demo RIG=emulated`: the same batch
# with the field drivers talking to the device emulators (rascal_drivers' rig --emulated).
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

case "${RIG:-sim}" in
  sim | emulated) ;;
  *) echo "demo: RIG=$RIG: expected sim (the default) or emulated"; exit 2 ;;
esac
if [ "${RIG:-sim}" = emulated ]; then
  # The field drivers on the device emulators, the emulators fed by the simulator: the master,
  # the configuration, sim, emulated_devices, arm_driver, scale_driver, arm_controller and
  # sherd_detector in order, each healthy before the next (src/rascal_drivers/README.md).
  echo "demo: context $context; emulated rig: arm_driver and scale_driver on the servo-bus and scale emulators"
  exec rosrun rascal_drivers rig --emulated --port 0 -- bash -c "
    rosrun rascal_tasks rascal run --context '$context' &&
    rosrun rascal_tasks rascal report --context '$context'"
fi

rosrun rascal_tasks rascal db migrate
echo "demo: context $context; simulator, arm_controller and sherd_detector start with rosrun"
# then what an archaeologist takes away: the printable report (HTML and PDF), the Field Desktop
# import files with the images, and a backup of the catalogue and archive that restores
mkdir -p var/exports var/backups
/usr/bin/python3 -m rascal_tasks.sim_rig -- bash -c "
  rosrun rascal_tasks rascal run --context '$context' &&
  rosrun rascal_tasks rascal report --context '$context' --pdf &&
  rosrun rascal_tasks rascal export --context '$context' --format field-desktop --output 'var/exports/$context' &&
  { rosrun rascal_tasks rascal backup --output 'var/backups/$context.backup'; rc=\$?;
    # 1: written, but rows of the catalogue name images this archive does not hold (contexts
    # recorded from another checkout into the same database): said above, one line each
    if [ \$rc -eq 1 ]; then echo 'demo: backup written; the images listed above are not in this archive'; fi
    [ \$rc -le 1 ]; }"
