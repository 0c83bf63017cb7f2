#!/usr/bin/env bash
# One idempotent set-up for a fresh Debian 12 machine (run as root, or with sudo available):
# Debian packages, a venv for pinned PyPI packages, the catkin build, and a PostgreSQL
# server for tests and the demo. A second run with nothing changed does no work (< 15 s).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
cd "$here"

# ---------------------------------------------------------------- Debian packages
APT_PACKAGES=(
  # ROS 1 (Debian's own packaging of Noetic-era ROS)
  ros-base-dev ros-core catkin python3-catkin-pkg python3-rospkg
  python3-rospy python3-roslaunch python3-rosparam python3-rosnode python3-rostopic
  python3-rosservice python3-rosgraph python3-rosunit python3-rosbag rosbash libroscpp-dev
  ros-message-generation ros-message-runtime python3-genmsg python3-genpy python3-gencpp
  ros-std-msgs libstd-msgs-dev python3-std-msgs ros-std-srvs libstd-srvs-dev python3-std-srvs
  ros-geometry-msgs libgeometry-msgs-dev python3-geometry-msgs
  ros-sensor-msgs libsensor-msgs-dev python3-sensor-msgs
  ros-trajectory-msgs libtrajectory-msgs-dev python3-trajectory-msgs
  ros-visualization-msgs libvisualization-msgs-dev python3-visualization-msgs
  ros-actionlib-msgs libactionlib-msgs-dev python3-actionlib-msgs libactionlib-dev python3-actionlib
  ros-tf2-msgs libtf2-msgs-dev python3-tf2-msgs libtf2-ros-dev python3-tf2-ros
  libtf2-geometry-msgs-dev libtf2-sensor-msgs-dev libtf2-eigen-dev libtf2-kdl-dev ros-rosgraph-msgs
  ros-robot-state-publisher rviz
  # kinematics, robot model
  liborocos-kdl-dev libkdl-parser-dev python3-pykdl liburdfdom-dev liburdfdom-tools libeigen3-dev
  # perception, simulation, collision
  libpcl-dev libpcl-conversions-dev libopencv-dev libopencv-contrib-dev python3-opencv
  libcv-bridge-dev python3-cv-bridge  # contrib: ArUco markers (simulator, rascal calibrate)
  libode-dev libfcl-dev libyaml-cpp-dev
  # build and test
  build-essential cmake googletest libgtest-dev python3-venv python3-pytest python3-numpy python3-yaml
  # catalogue
  postgresql-15 postgresql-client-15 python3-psycopg2
  # pictures of rviz without a screen
  xvfb xauth
  # field rig drivers (rascal_drivers): the scale's serial line, the DSLR through libgphoto2
  python3-serial python3-gphoto2
  chromium poppler-utils fonts-dejavu-core  # rascal report --pdf (headless print) and its tests
)
# dpkg-query answers in a fraction of a second, so the check runs every time; a package it has
# never heard of prints nothing, which also counts as missing.
installed=$(dpkg-query -W -f='${db:Status-Abbrev} ${Package}\n' "${APT_PACKAGES[@]}" 2>/dev/null \
            | awk '$1=="ii"{print $2}' || true)
missing=()
for p in "${APT_PACKAGES[@]}"; do grep -qx "$p" <<<"$installed" || missing+=("$p"); done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${APT_PACKAGES[@]}" >/dev/null
  scripts/postgres.sh restart-if-running
fi
mkdir -p .setup

# ---------------------------------------------------------------- Python venv (PyPI, pinned)
# Made from Debian's python so that rospy, psycopg2 and cv2 stay visible.
VENV=.venv
if [ ! -x "$VENV/bin/python" ]; then
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
fi
req=requirements.txt
if [ "$(cat .setup/pip.stamp 2>/dev/null)" != "$(sha256sum "$req" | cut -c1-16)" ]; then
  "$VENV/bin/pip" install -q --disable-pip-version-check -r "$req"
  sha256sum "$req" | cut -c1-16 > .setup/pip.stamp
fi

# ---------------------------------------------------------------- catkin build
if [ ! -f build/Makefile ]; then
  # Python3_EXECUTABLE too: Debian's kdl_parser -> urdf -> pluginlib pulls in ament_cmake_core,
  # which otherwise runs the first python3 on PATH (a pyenv one here, without ament_package).
  cmake -S . -B build -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
        -DCATKIN_DEVEL_PREFIX="$here/devel" \
        -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON >/dev/null
fi
make -C build -j"$(nproc)" --no-print-directory -s 2>&1 | grep -vE '^(\[|-- )' || true
test "${PIPESTATUS[0]}" -eq 0
make -C build -j"$(nproc)" --no-print-directory -s tests 2>&1 | grep -vE '^(\[|-- )' || true
test "${PIPESTATUS[0]}" -eq 0

# ---------------------------------------------------------------- PostgreSQL for tests and demo
scripts/postgres.sh start
