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
  install_debs deps build-essential cmake pkg-config \
    ros-base-dev ros-desktop-dev librostest-dev python3-rostest rosbash \
    rviz librviz-dev libtf2-ros-dev liburdfdom-dev liburdf-dev \
    ros-visualization-msgs python3-visualization-msgs \
    libeigen3-dev libtinyxml2-dev libyaml-cpp-dev libcli11-dev \
    libgtest-dev libbenchmark-dev python3-matplotlib python3-numpy \
    xvfb x11-utils ffmpeg
fi
