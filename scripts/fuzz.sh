#!/usr/bin/env bash
# Bounded libFuzzer runs of the NIfTI reader, the DICOM series assembly and the scene-file parser.
#
# Usage (from any folder):
#   bash scripts/fuzz.sh                       # build the targets, fuzz each for 15 s
#   FUZZ_SECONDS=600 bash scripts/fuzz.sh      # longer runs
#   FUZZ_TARGETS=fuzz_nifti bash scripts/fuzz.sh   # one target only
#   VB_FUZZ_VERBOSE=1 build/fuzz/fuzz_nifti FILE   # replay one input (a finding, a seed);
#       give files, not a folder: libFuzzer adds new inputs to a folder it is given
#
# Needs the CMake configure step first (scripts/build.sh, or cmake -B build): the sources include
# ${BUILD_DIR}/generated/voxbreast/config.hpp, which CMake generates. Needs clang++ (Debian clang
# 14 with libclang-rt-14-dev for libFuzzer) and the project's libraries (DCMTK, nifti_clib, zlib).
#
# Environment:
#   BUILD_DIR      CMake build folder (default build, relative to the repository root)
#   FUZZ_SECONDS   seconds of fuzzing per target (default 15); the targets run at once
#   FUZZ_CXX       compiler (default clang++)
#   FUZZ_TARGETS   targets to build and run (default all three: fuzz_nifti fuzz_dicom_series
#                  fuzz_scene_file)
#
# Targets and objects go to ${BUILD_DIR}/fuzz/ (objects are rebuilt only when a source, a header
# it includes or the flags change). Each target fuzzes a fresh copy of tests/fuzz/corpus/<name>/
# in ${BUILD_DIR}/fuzz/corpus-run/, so the committed seeds are never modified. A crash, sanitizer
# report, timeout (> 10 s for one input) or out-of-memory (> 2048 MB) is saved as
# ${BUILD_DIR}/fuzz/findings/<target>/crash-*|timeout-*|oom-* and the script exits 1; the full
# log is ${BUILD_DIR}/fuzz/<target>.log. Exit 2: cannot build or set up.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

build_dir=${BUILD_DIR:-build}
[[ $build_dir = /* ]] || build_dir=$root/$build_dir
seconds=${FUZZ_SECONDS:-15}
cxx=${FUZZ_CXX:-clang++}
targets=${FUZZ_TARGETS:-fuzz_nifti fuzz_dicom_series fuzz_scene_file}
out=$build_dir/fuzz

fail_setup() {
  echo "fuzz.sh: $*" >&2
  exit 2
}

[[ -f $build_dir/generated/voxbreast/config.hpp ]] ||
  fail_setup "$build_dir/generated/voxbreast/config.hpp is missing: configure the CMake build" \
    "first (bash scripts/build.sh, or cmake -B $build_dir -G Ninja), or set BUILD_DIR"
command -v "$cxx" >/dev/null || fail_setup "$cxx not found: install clang (and libclang-rt-dev)"
[[ $seconds =~ ^[0-9]+$ && $seconds -gt 0 ]] || fail_setup "FUZZ_SECONDS must be a positive integer"

cxxflags=(-std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined,float-cast-overflow -fno-omit-frame-pointer
  -DTOML_HEADER_ONLY=0 -DTOML_SHARED_LIB=1
  -I"$root" -I"$build_dir/generated" -I/usr/include/eigen3 -I/usr/include/nifti)
libs=(-ldcmjpls -ldcmjpeg -ldcmimage -ldcmimgle -ldcmdata -loflog -lofstd
  -lnifti2 -lznz -ltomlplusplus -lz -lm -lpthread)

# Project sources each target needs (listed explicitly; keep in step with their #includes).
common_sources=(engine/error.cpp io/atomic_file.cpp)
declare -A target_sources=(
  [fuzz_nifti]="tests/fuzz/fuzz_nifti.cpp io/nifti_io.cpp io/gzip_blocks.cpp"
  [fuzz_dicom_series]="tests/fuzz/fuzz_dicom_series.cpp io/dicom_read.cpp io/dicom_pixels.cpp io/dicom_deflate.cpp io/dicom_attributes.cpp"
  [fuzz_scene_file]="tests/fuzz/fuzz_scene_file.cpp io/scene_file.cpp io/toml_section.cpp io/toml_text.cpp io/did_you_mean.cpp io/indenter_path_csv.cpp io/numeric_csv.cpp engine/material/default_materials.cpp engine/material/hyperelastic.cpp engine/loads/posture.cpp io/scene_overrides.cpp"
)
declare -A target_corpus=([fuzz_nifti]=nifti [fuzz_dicom_series]=dicom [fuzz_scene_file]=scene)
for t in $targets; do
  [[ -n ${target_sources[$t]:-} ]] || fail_setup "unknown target $t (known: ${!target_sources[*]})"
done

mkdir -p "$out/obj"
flag_stamp="$cxx ${cxxflags[*]}"

# Object of one source; true when it must be (re)compiled.
object_of() { local s=$1; echo "$out/obj/${s//\//__}.o"; }
stale() {
  local src=$1 obj dep f
  obj=$(object_of "$src")
  dep=${obj%.o}.d
  [[ -f $obj && -f $dep && -f $obj.flags ]] || return 0
  [[ $(<"$obj.flags") == "$flag_stamp" ]] || return 0
  for f in $(sed -e 's/\\$//' -e 's/^[^:]*://' "$dep"); do
    [[ -e $f && ! $f -nt $obj ]] || return 0
  done
  return 1
}

compile() {
  local src=$1 obj
  obj=$(object_of "$src")
  "$cxx" "${cxxflags[@]}" -MMD -MF "${obj%.o}.d" -c "$src" -o "$obj" &&
    printf '%s' "$flag_stamp" >"$obj.flags"
}

# Compile what is stale, in parallel (one job per source), then link.
build_start=$SECONDS
sources=("${common_sources[@]}")
for t in $targets; do read -ra extra <<<"${target_sources[$t]}"; sources+=("${extra[@]}"); done
pids=()
for src in "${sources[@]}"; do
  if stale "$src"; then
    echo "fuzz.sh: compiling $src"
    compile "$src" &
    pids+=($!)
  fi
done
for pid in "${pids[@]}"; do wait "$pid" || fail_setup "compilation failed (see above)"; done
for t in $targets; do
  read -ra extra <<<"${target_sources[$t]}"
  objects=()
  for src in "${common_sources[@]}" "${extra[@]}"; do objects+=("$(object_of "$src")"); done
  "$cxx" "${cxxflags[@]}" "${objects[@]}" "${libs[@]}" -o "$out/$t" ||
    fail_setup "linking $t failed"
done
echo "fuzz.sh: built ${targets} in $((SECONDS - build_start)) s"

# Sanitizer settings: any UBSan report is fatal; stacks symbolized when llvm-symbolizer exists.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=0:detect_leaks=1}
if symbolizer=$(command -v llvm-symbolizer || command -v llvm-symbolizer-14); then
  export ASAN_SYMBOLIZER_PATH=${ASAN_SYMBOLIZER_PATH:-$symbolizer}
fi

run_target() {
  local t=$1 corpus=$out/corpus-run/${target_corpus[$1]} findings=$out/findings/$1
  local scratch=$out/tmp-$1
  rm -rf "$corpus" "$scratch"
  mkdir -p "$corpus" "$findings" "$scratch"
  cp -R "tests/fuzz/corpus/${target_corpus[$t]}/." "$corpus/"
  # TMPDIR: the targets' temporary files; removed below even if a crash skipped their atexit.
  # nifti_clib prints "** ERROR ..." for every header it rejects (its debug level does not
  # silence those): dropped from the log, which would otherwise grow by megabytes a minute.
  set +e
  TMPDIR=$scratch "$out/$t" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 -artifact_prefix="$findings/" "$corpus" 2>&1 |
    grep --line-buffered -vE '^\*\* (ERROR|WARNING)' >"$out/$t.log"
  local rc=${PIPESTATUS[0]}
  set -e
  rm -rf "$scratch"
  return "$rc"
}

declare -A run_pid
run_start=$SECONDS
for t in $targets; do
  run_target "$t" &
  run_pid[$t]=$!
done
status=0
for t in $targets; do
  if wait "${run_pid[$t]}"; then
    echo "fuzz.sh: $t ok: $(grep -E '^#[0-9]+[[:space:]]+DONE' "$out/$t.log" | tail -1 || true)"
  else
    status=1
    echo "fuzz.sh: $t FAILED; log $out/$t.log, findings in $out/findings/$t/:" >&2
    ls -1 "$out/findings/$t/" >&2 || true
    tail -n 60 "$out/$t.log" >&2
    echo "fuzz.sh: replay with: $out/$t $out/findings/$t/<file>" >&2
  fi
done
echo "fuzz.sh: fuzzed ${seconds} s per target in $((SECONDS - run_start)) s wall"
exit "$status"
