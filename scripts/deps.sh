#!/usr/bin/env bash
# Installs the Debian packages nscd_sim needs (idempotent; needs root or sudo).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
PKGS=(build-essential cmake pkg-config
  ros-base-dev ros-desktop-dev librostest-dev python3-rostest rosbash
  rviz librviz-dev libtf2-ros-dev liburdfdom-dev liburdf-dev
  ros-visualization-msgs python3-visualization-msgs
  libeigen3-dev libtinyxml2-dev libyaml-cpp-dev libcli11-dev
  libgtest-dev libbenchmark-dev python3-matplotlib python3-numpy
  xvfb x11-utils ffmpeg)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "deps: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
