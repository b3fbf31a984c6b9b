#!/usr/bin/env bash
# Installs everything speculum needs from Debian 12's packages. Safe to run again.
set -euo pipefail
SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends \
  g++ cmake ninja-build pkg-config \
  libglm-dev libopenimageio-dev openimageio-tools libpng-dev \
  libtinygltf-dev nlohmann-json3-dev libstb-dev libtinyobjloader-dev \
  libopenmesh-dev libtbb-dev libnanoflann-dev \
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev \
  assimp-testmodels graphviz libembree-dev \
  ccache chromium libexpat1-dev parallel gnuplot-nox libosmesa6-dev \
  clang-14 libclang-rt-14-dev
