#!/usr/bin/env bash
# Installs the Debian packages evfs needs to build, test and benchmark.
# Idempotent: when everything is present it only runs dpkg-query and exits.
# With --fuzz it also installs clang and its libFuzzer runtime (for `make fuzz` only).
# With --train it also installs what training the residual denoiser needs (`make train-denoiser`
# only): PyTorch, ONNX, OpenCV's Python module, and the images and videos it trains on.
# With --with-browser it also installs Chromium, which report_browser_test opens report.html in.
set -euo pipefail

packages=(
  cmake make g++ pkg-config
  # The clang_format test (tests/CMakeLists.txt).
  clang-format
  libceres-dev libeigen3-dev libgoogle-glog-dev libgflags-dev
  libopencv-dev libpng-dev libhdf5-dev libgtest-dev libgmock-dev libbenchmark-dev
  # summary.json (app/reconstruct_job.cc).
  nlohmann-json3-dev
  # AEDAT 4 (io/aedat4/); the python3 modules decode the real samples independently in tests.
  libflatbuffers-dev flatbuffers-compiler liblz4-dev libzstd-dev libtinyxml2-dev
  python3-lz4 python3-zstandard python3-flatbuffers
  # ROS 1 bags: rosbag_storage reads the container (its bag.h includes pluginlib, which includes
  # the ROS 2 headers below; io/CMakeLists.txt finds them); python3-rosbag writes the test bags
  # (tests/io/write_rosbag.py) independently of evfs.
  librosbag-storage-dev pluginlib-dev libclass-loader-dev librcpputils-dev librcutils-dev
  libament-index-cpp-dev libroscpp-core-dev libconsole-bridge-dev python3-rosbag python3-pil
  # benchmarks/plot_methods.py: method_benchmark's PSNR-against-time plots.
  python3-matplotlib
  # The Python module (python/) and its pytest suite.
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest
  # mpirun -np N evfs video (app/video_mpi.cc, EVFS_WITH_MPI); evfs builds without it too.
  libopenmpi-dev openmpi-bin
)
if [ "${1:-}" = "--fuzz" ]; then
  packages+=(clang libclang-rt-dev)
fi
if [ "${1:-}" = "--with-browser" ]; then
  packages+=(chromium)
fi
if [ "${1:-}" = "--train" ]; then
  packages+=(python3-torch python3-onnx python3-opencv python3-numpy opencv-doc python3-skimage)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
