#!/usr/bin/env bash
# Installs the Debian packages nscd_sim needs (idempotent; needs root or sudo).
# Sourced (scripts/install_siconos.sh), it only defines install_debs.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

# install_debs NAME PACKAGE...: installs those of the packages that are missing;
# NAME prefixes the status line.
install_debs() {
  local name=$1 p
  shift
  local missing=()
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    echo "$name: all $# packages present"
    return 0
  fi
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "$name: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -q
  $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
}

if [ "${BASH_SOURCE[0]}" = "$0" ]; then
  # Build: compilers, catkin, ROS 1 C++ libraries and message headers, Eigen, parsers, tests.
  # Tools the scripts, launch files and tests call: roslaunch/rosrun/rostest, rosservice
  # (record_video.sh pauses the node), rostopic/rosbag (docs/node.md; python3-rosbag also
  # holds rosbag's play and record that launch/c60_playback.launch runs; rospy: the
  # rosbag round-trip test and record_video.sh --stills), and the Python
  # message packages those tools load for every type the node publishes or serves.
  # Off-screen recording: Xvfb, xwininfo, ffmpeg. Plots: matplotlib. bc: c60_bench.sh.
  # The RViz panel plugin: librviz-dev, qtbase5-dev (Qt5 Widgets, moc); its test: xvfb.
  # nscd_actuator_markers (drag the C-60 handle and probe in RViz): libinteractive-markers-dev.
  # The Python module (docs/python.md): pybind11-dev, python3-dev, python3-setuptools
  # (setup.py for catkin_python_setup); its tests: python3-pytest; studies on a Dask
  # cluster: python3-distributed. The libFuzzer targets (scripts/fuzz.sh, docs/fuzzing.md):
  # clang-14 and its sanitizer/libFuzzer runtimes, libclang-rt-14-dev; FCLib and HDF5
  # (libfclib-dev, libhdf5-dev): the fclib_reader target and tools/fclib's reader test.
  install_debs deps build-essential cmake pkg-config \
    ros-base-dev ros-desktop-dev librostest-dev python3-rostest rosbash \
    python3-roslaunch python3-rosservice python3-rostopic python3-rosbag python3-rosnode python3-rospy \
    python3-rosparam python3-rosmsg rospack-tools \
    python3-std-msgs python3-std-srvs python3-geometry-msgs python3-diagnostic-msgs \
    python3-tf2-msgs python3-rosgraph-msgs python3-sensor-msgs python3-visualization-msgs \
    rviz librviz-dev qtbase5-dev libinteractive-markers-dev libtf2-ros-dev liburdfdom-dev liburdf-dev ros-visualization-msgs libsensor-msgs-dev \
    libeigen3-dev libtinyxml2-dev libyaml-cpp-dev libcli11-dev \
    libgtest-dev libbenchmark-dev python3-matplotlib python3-numpy \
    xvfb xauth x11-utils ffmpeg bc \
    pybind11-dev python3-dev python3-setuptools python3-pytest python3-distributed \
    clang-14 libclang-rt-14-dev libfclib-dev libhdf5-dev
fi
