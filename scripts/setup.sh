#!/usr/bin/env bash
# Installs the Debian packages this package needs (only when some are missing),
# wraps the repository in a catkin workspace under build/ws and builds it in Release.
# Sourced by run_demo.sh and run_tests.sh; safe to run again (incremental build).
set -euo pipefail

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${BTR_WS:-$REPO_ROOT/build/ws}"   # BTR_WS: another workspace (the sanitizer build)
PKG=breast_tumour_registration

DEB_PACKAGES=(
  ros-core-dev libtf2-ros-dev libtf2-eigen-dev libpcl-conversions-dev libpcl-dev
  libcgal-dev libsuitesparse-dev libeigen3-dev python3-rostest librostest-dev
  python3-rosbag librosbag-dev ros-message-generation libstd-srvs-dev python3-roslaunch
  rosbash python3-rosservice  # rosrun, rosservice: the README's commands
  libsensor-msgs-dev libshape-msgs-dev libvisualization-msgs-dev libgeometry-msgs-dev libdiagnostic-msgs-dev
  libtf2-msgs-dev
  libnifti2-dev libteem-dev nlohmann-json3-dev  # label maps (NIfTI, NRRD) and Slicer markups (issue 15)
  libopenblas0-pthread libyaml-cpp-dev libcli11-dev libgtest-dev libbenchmark-dev
  libcairo2-dev fonts-dejavu-core  # the cross-section picture (axes, legend)
  python3-matplotlib python3-numpy pkg-config cmake g++ make time
  clang libclang-rt-14-dev  # libFuzzer + sanitizers for scripts/run_fuzz.sh (part of the tests)
)

# BTR_EXTRA_PACKAGES: further Debian packages a caller needs (scripts/render_rviz.sh: rviz, xvfb).
read -r -a extra_packages <<< "${BTR_EXTRA_PACKAGES:-}"
DEB_PACKAGES+=("${extra_packages[@]}")
missing=()
for p in "${DEB_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "[setup] installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "[setup] all Debian packages present"
fi

# catkin wants <ws>/src/<package>; the repository root is the package. The package folder
# links every top-level entry of the repository except build/ and out/: a single link to
# the root would contain itself, and roslaunch's file search would recurse forever.
mkdir -p "$WS/src"
[ -L "$WS/src/$PKG" ] && rm "$WS/src/$PKG"
mkdir -p "$WS/src/$PKG"
for entry in "$REPO_ROOT"/* "$REPO_ROOT"/.ci; do
  name="$(basename "$entry")"
  case "$name" in build|out) continue ;; esac
  ln -sfn "$entry" "$WS/src/$PKG/$name"
done
# Drop links to entries that no longer exist.
find "$WS/src/$PKG" -maxdepth 1 -xtype l -delete

# The pyenv python3 on PATH lacks catkin_pkg: always use Debian's interpreter.
export PATH="/usr/bin:$PATH"
JOBS="${BTR_JOBS:-$(nproc)}"
cd "$WS"
echo "[setup] building in $WS (Release, $JOBS jobs)"
# BTR_CMAKE_ARGS: further CMake arguments separated by '|' (the sanitizer build's flags).
extra=()
[ -n "${BTR_CMAKE_ARGS:-}" ] && IFS='|' read -r -a extra <<< "$BTR_CMAKE_ARGS"
catkin_make -j"$JOBS" -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE="${BTR_BUILD_TYPE:-Release}" \
  -DCATKIN_ENABLE_TESTING=ON "${extra[@]}" "$@"
