#!/usr/bin/env bash
# Installs the OPTIONAL Debian packages of the Siconos / FCLib comparisons
# (issue 6: bench/siconos, tools/fclib). Not needed to build, test or run nscd_sim;
# CI does not install them. Idempotent; needs root or sudo. Then rebuild
# (scripts/build.sh): bench/siconos.cmake adds nscd_siconos_compare and nscd_fclib.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
PKGS=(libsiconos-kernel-dev libsiconos-numerics-dev python3-siconos libfclib-dev libhdf5-dev
  python3-numpy python3-matplotlib)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_siconos: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install_siconos: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
