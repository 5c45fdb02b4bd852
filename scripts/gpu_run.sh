#!/usr/bin/env bash
# Runs voxbreast on a machine that has NVIDIA's OpenCL driver but no ICD loader, no nvidia.icd and
# no Debian packages (the device machine).
#   here:  bash scripts/gpu_run.sh prepare        # bundles the built binary, its shared libraries
#                                                 # and the ICD loader into .device-pkgs/ (git-ignored)
#   there: bash scripts/gpu_run.sh run voxbreast bench --out $OUT/bench
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
pkgs=$root/.device-pkgs

case "${1:-}" in
  prepare)
    build=${VOXBREAST_BUILD_DIR:-$root/build}
    rm -rf "$pkgs" && mkdir -p "$pkgs/bin" "$pkgs/lib" "$pkgs/deb"
    cp "$build/apps/voxbreast" "$build/tests/test_physics" "$pkgs/bin/"
    for t in test_fit test_probing test_force_feedback; do  # every test binary that runs OpenCL
      if [[ -x "$build/tests/$t" ]]; then cp "$build/tests/$t" "$pkgs/bin/"; fi
    done
    # Every shared library the binary needs except the C runtime the device already has.
    ldd "$build/apps/voxbreast" | awk '/=> \// {print $3}' | grep -vE '/(libc|libm|libdl|libpthread|librt|libresolv|ld-linux[^/]*)\.so' |
      while read -r lib; do cp -L "$lib" "$pkgs/lib/"; done
    (cd "$pkgs/deb" && apt-get download ocl-icd-libopencl1 clinfo >/dev/null)
    cp "$(dpkg -L libdcmtk17 2>/dev/null | grep '/dicom.dic$' | head -1)" "$pkgs/lib/"  # DCMTK's dictionary
    # One xz archive keeps the carried folder under the device tool's 64 MiB (libicudata is 30 MB).
    tar -C "$pkgs" -cJf "$pkgs/bundle.tar.xz" bin lib && rm -rf "$pkgs/bin" "$pkgs/lib"
    du -sh "$pkgs"
    ;;
  run)
    shift
    tmp=$(mktemp -d)
    tar -C "$tmp" -xJf "$pkgs/bundle.tar.xz"
    for deb in "$pkgs"/deb/*.deb; do dpkg -x "$deb" "$tmp/root"; done
    mkdir -p "$tmp/icd"
    echo "libnvidia-opencl.so.1" >"$tmp/icd/nvidia.icd"
    export OCL_ICD_VENDORS=$tmp/icd
    export LD_LIBRARY_PATH=$tmp/root/usr/lib/x86_64-linux-gnu:$tmp/lib:${LD_LIBRARY_PATH:-}
    export PATH=$tmp/bin:$tmp/root/usr/bin:$PATH
    export DCMDICTPATH=$tmp/lib/dicom.dic
    "$@"
    ;;
  *)
    echo "usage: $0 prepare | run COMMAND..." >&2
    exit 2
    ;;
esac
