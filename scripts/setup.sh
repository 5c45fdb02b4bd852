#!/usr/bin/env bash
# Installs every Debian package VoxBreast needs to build, test and plot.
# Idempotent: packages already present are left alone. Run as root (or via sudo).
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  ocl-icd-opencl-dev opencl-c-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  libeigen3-dev libhdf5-dev hdf5-tools
  libgtest-dev googletest
  libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
  libssl-dev libpugixml-dev python3-lxml
  libdcmtk-dev dcmtk libnifti2-dev python3-pydicom python3-nibabel clang libclang-rt-14-dev
  python3 python3-matplotlib python3-numpy python3-h5py python3-vtk9
  libopenmpi-dev openmpi-bin
  python3-dolfinx
  plastimatch elastix dicom3tools python3-meshio
  ccache
  libcivetweb-dev chromium curl
)
# node and npm bundle the page of `voxbreast view` (apps/web); Debian's own when none is on PATH.
command -v node >/dev/null || packages+=(nodejs)
command -v npm >/dev/null || packages+=(npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages already installed"
else
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The page's JavaScript packages, exactly as package-lock.json pins them. Puppeteer drives the
# system chromium in the browser tests and must not download a browser of its own.
web=$(cd "$(dirname "$0")/../apps/web" && pwd)
if [[ ! -d $web/node_modules ]] || [[ $web/package-lock.json -nt $web/node_modules/.package-lock.json ]]; then
  echo "setup: npm ci in apps/web"
  (cd "$web" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error)
fi
