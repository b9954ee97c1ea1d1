#!/usr/bin/env bash
# Installs every dependency of isoflex from Debian 12 packages (idempotent; run as root) and
# builds the Release-with-assertions configuration into build/ (executable: build/isoflex).
# `setup.sh --fuzz` installs clang and libFuzzer too (for the preset fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(g++ cmake ninja-build ccache pkg-config
  libeigen3-dev libyaml-cpp-dev libcli11-dev libfmt-dev libmuparser-dev
  libgtest-dev libbenchmark-dev python3-matplotlib python3-yaml python3-scipy
  pybind11-dev python3-dev python3-numpy
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libtbb-dev libsuitesparse-dev
  libopenblas0-serial libhdf5-dev python3-h5py petsc-dev)
# --fuzz: also clang and libFuzzer for the libFuzzer harnesses (preset fuzz, README
# "Development"); the default setup and CI do not need them.
if [[ ${1:-} == --fuzz ]]; then packages+=(clang libclang-rt-14-dev); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  if [[ $(id -u) -ne 0 ]]; then SUDO=sudo; else SUDO=; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 "${missing[@]}"
fi

cmake --preset release >/dev/null
cmake --build --preset release
