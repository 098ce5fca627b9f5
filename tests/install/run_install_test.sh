#!/usr/bin/env bash
# run_install_test.sh BUILD_DIR WORK_DIR BUNDLE_DIR CONSUMER_SOURCE CMAKE GENERATOR CC CXX
# Installs the loader component of BUILD_DIR into WORK_DIR/prefix, builds and runs the consumer
# through find_package and through pkg-config, checks what the binaries link, and runs the
# installed exitance-view.
set -euo pipefail
build_dir=$1 work=$2 bundle=$3 consumer=$4 cmake=$5 generator=$6 cc=$7 cxx=$8
forbidden='libvulkan|libembree|libopenvdb|libCGAL|libtbb'

rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
"$cmake" --install "$build_dir" --component loader --prefix "$prefix" >"$work/install.log"

library=$(find "$prefix" -name 'libexitance_loader.so*' -type f | head -n1)
[ -n "$library" ] || { echo "FAIL: libexitance_loader.so not installed under $prefix"; exit 1; }
pcdir=$(dirname "$(find "$prefix" -name exitance.pc | head -n1)")

check_links() {  # binary [forbidden-regex]: no forbidden library, directly or through dependencies
  local binary=$1 forbidden=${2:-$forbidden} needed resolved
  needed=$(readelf -d "$binary" | grep NEEDED || true)
  resolved=$(LD_LIBRARY_PATH="$(dirname "$library")" ldd "$binary")
  echo "--- $binary"
  echo "$needed"
  if grep -Eq "$forbidden" <<<"$needed$resolved"; then
    echo "FAIL: $binary links a forbidden library:"
    grep -E "$forbidden" <<<"$needed$resolved"
    exit 1
  fi
  if grep -q 'not found' <<<"$resolved"; then
    echo "FAIL: $binary has unresolved libraries:"
    grep 'not found' <<<"$resolved"
    exit 1
  fi
}

check_links "$library"
for mode in find_package pkg-config; do
  out="$work/consumer-$mode"
  PKG_CONFIG_PATH="$pcdir" "$cmake" -S "$consumer" -B "$out" -G "$generator" \
    -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
    -DCMAKE_PREFIX_PATH="$prefix" -DCONSUMER_USE="$mode" >"$out.configure.log" 2>&1 \
    || { cat "$out.configure.log"; echo "FAIL: configuring the $mode consumer"; exit 1; }
  "$cmake" --build "$out" >"$out.build.log" 2>&1 || { cat "$out.build.log"; echo "FAIL: building the $mode consumer"; exit 1; }
  check_links "$out/consumer"
  # The consumer links the loader alone: OpenEXR comes in only through libexitance_loader.so.
  if readelf -d "$out/consumer" | grep NEEDED | grep -qi openexr; then
    echo "FAIL: the $mode consumer links OpenEXR directly"
    exit 1
  fi
  readelf -d "$out/consumer" | grep NEEDED | grep -q 'libexitance_loader' \
    || { echo "FAIL: the $mode consumer does not link libexitance_loader"; exit 1; }
  # Run it without LD_LIBRARY_PATH: the build tree's RPATH must find the installed library.
  "$out/consumer" "$bundle" || { echo "FAIL: the $mode consumer failed on $bundle"; exit 1; }
done
# exitance-view comes with the loader: beyond it only the machine's Vulkan loader (libvulkan.so.1,
# for --path-traced, as exitance-relight leaves it to the machine), and it runs from the prefix.
view="$prefix/bin/exitance-view"
[ -x "$view" ] || { echo "FAIL: exitance-view not installed under $prefix/bin"; exit 1; }
check_links "$view" 'libembree|libopenvdb|libCGAL|libtbb'
if readelf -d "$view" | grep NEEDED | grep -Eqi 'OpenImageIO|libexitance_runtime'; then
  echo "FAIL: exitance-view links more than the loader and the Vulkan loader"
  exit 1
fi
"$view" --help >/dev/null || { echo "FAIL: the installed exitance-view does not run"; exit 1; }
echo "installed loader: find_package and pkg-config consumers built, ran, and link no forbidden library; exitance-view runs"
