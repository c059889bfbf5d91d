#!/usr/bin/env bash
# Installs the OPTIONAL Debian packages of the Siconos / FCLib comparisons
# (bench/siconos, tools/fclib). Not needed to build, test or run nscd_sim;
# CI does not install them. Idempotent; needs root or sudo. Then rebuild
# (scripts/build.sh): bench/siconos.cmake adds nscd_siconos_compare and nscd_fclib.
source "$(dirname "${BASH_SOURCE[0]}")/deps.sh"  # install_debs
install_debs install_siconos libsiconos-kernel-dev libsiconos-numerics-dev python3-siconos \
  libfclib-dev libhdf5-dev python3-numpy python3-matplotlib
