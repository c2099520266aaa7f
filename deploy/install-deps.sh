#!/usr/bin/env bash
# Installs everything graspsim needs on Debian 12, and nothing twice.
# Idempotent: packages already present are skipped; a second run is quiet and takes about a second.
set -euo pipefail

DEBIAN_PACKAGES=(
  build-essential cmake ninja-build ccache pkg-config
  libgrpc++-dev protobuf-compiler-grpc libprotobuf-dev protobuf-compiler
  libeigen3-dev libembree-dev libpcl-dev libopencv-dev libflann-dev libmodbus-dev
  liburdfdom-dev libassimp-dev libqhull-dev libompl-dev libsqlite3-dev
  libcpp-httplib-dev libgtest-dev libgmock-dev libbenchmark-dev octave
  libssl-dev openssl python3 python3-venv python3-pip  # openssl: the CLI makes test certificates (tests/python/test_security.py)
  nodejs chromium chromium-driver
  libtinyxml2-dev  # MJCF (MuJoCo XML) robot files: server/src/import/mjcf_*.cpp
  libsdformat-dev  # SDF robot and world files (libsdformat 12): server/src/import/sdf_*.cpp
  clang libclang-rt-14-dev  # libFuzzer targets and the ASan/UBSan build of the C++ tests (docs/fuzzing.md)
  libzstd-dev liblz4-dev zlib1g-dev  # MCAP recordings: chunk compression and CRCs (server/src/recording)
  libboost-dev  # Boost.Beast: the Foxglove WebSocket endpoint (server/src/live)
  nlohmann-json3-dev  # JSON of the Foxglove WebSocket protocol (server/src/live); Boost 1.74's JSON is not header-only
  libmujoco-dev libbullet-dev  # the MuJoCo and Bullet engines behind server/src/physics/engine.h (issue 21)
  curl  # the docs' HTTP examples run in make test (tests/python/test_doc_examples.py)
  haproxy  # the fleet's gRPC load balancer, run on loopback by tests/python/test_fleet.py and tests/bench/run fleet
)

missing=()
for pkg in "${DEBIAN_PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

# The browser viewer is bundled with npm. Debian ships npm as its own package, but a nodejs from elsewhere
# (nodesource) bundles npm and conflicts with Debian's: ask for the package only when the command is missing.
if ! command -v npm >/dev/null 2>&1; then missing+=(npm); fi

if ((${#missing[@]})); then
  echo "install-deps: installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  # The package lists may be stale or absent on a fresh machine; refresh once, only when we install.
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
