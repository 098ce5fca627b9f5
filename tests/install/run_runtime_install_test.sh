#!/usr/bin/env bash
# run_runtime_install_test.sh BUILD_DIR WORK_DIR CMAKE
# Installs the runtime component of BUILD_DIR into WORK_DIR/prefix (exitance-relight, the shared
# libexitance_runtime and the few shared libraries they need) and checks that the folder is
# relocatable and links nothing of the offline stage: no Embree, TBB, OpenImageIO, OpenVDB, CGAL;
# the shared library uses the system's libstdc++ (no static C++ runtime inside a .so); a C program
# builds against the installed headers and library.
set -euo pipefail
build_dir=$1 work=$2 cmake=$3
forbidden='libembree|libtbb|libOpenImageIO|libopenvdb|libCGAL|libtinygltf|libssl|libcrypto'

rm -rf "$work"
mkdir -p "$work"
"$cmake" --install "$build_dir" --component runtime --prefix "$work/prefix" >"$work/install.log"
# Relocatable: move the installed folder somewhere else before using it.
mv "$work/prefix" "$work/moved"
tool="$work/moved/bin/exitance-relight"
library=$(find "$work/moved/lib" -name 'libexitance_runtime.so.*' -type f | head -n1)
[ -x "$tool" ] || { echo "FAIL: exitance-relight not installed"; exit 1; }
[ -n "$library" ] || { echo "FAIL: libexitance_runtime.so not installed"; exit 1; }

for binary in "$tool" "$library"; do
  needed=$(readelf -d "$binary" | grep NEEDED || true)
  resolved=$(env -i ldd "$binary")
  echo "--- $binary"
  echo "$needed"
  if grep -Eq "$forbidden" <<<"$needed$resolved"; then
    echo "FAIL: $binary links a library of the offline stage:"; grep -E "$forbidden" <<<"$needed$resolved"; exit 1
  fi
  if grep -q 'not found' <<<"$resolved"; then
    echo "FAIL: $binary has unresolved libraries in the moved folder:"; grep 'not found' <<<"$resolved"; exit 1
  fi
  # Everything beyond the system's C/C++ runtimes and the Vulkan loader comes from the folder itself.
  outside=$(grep '=>' <<<"$resolved" | grep -v "$work/moved" |
            grep -Ev 'libc\.so|libm\.so|libstdc\+\+|libgcc_s|libvulkan|ld-linux|libpthread|libdl\.so|librt\.so' || true)
  if [ -n "$outside" ]; then echo "FAIL: $binary resolves libraries outside the folder:"; echo "$outside"; exit 1; fi
done
readelf -d "$library" | grep NEEDED | grep -q 'libstdc++' \
  || { echo "FAIL: libexitance_runtime.so does not use the shared libstdc++"; exit 1; }

# An engine's C program compiles against the installed headers and links the installed library.
cat >"$work/engine.c" <<'C'
#include <stdio.h>
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"
int main(int argc, char** argv) {
  ExitanceRuntime* rt = NULL;
  ExitanceRuntimeError e = exitance_runtime_open_on_device(argv[1], NULL, NULL, &rt);
  printf("%d %s\n", (int)e, exitance_runtime_last_error_message());
  return e == EXITANCE_RUNTIME_INVALID_ARGUMENT && rt == NULL ? 0 : 1;
}
C
cc -std=c99 -pedantic-errors -I"$work/moved/include" "$work/engine.c" -L"$(dirname "$library")" -lexitance_runtime \
   -Wl,-rpath,"$(dirname "$library")" -o "$work/engine" || { echo "FAIL: a C program does not build against the installed runtime"; exit 1; }
"$work/engine" "$work/no-such-bundle" || { echo "FAIL: the installed runtime's C API"; exit 1; }

env -i "$tool" --help >/dev/null || { echo "FAIL: exitance-relight --help"; exit 1; }
set +e
env -i "$tool" "$work/no-such-bundle" 2>"$work/err.txt"
status=$?
set -e
[ "$status" -eq 2 ] || { echo "FAIL: a missing bundle gave exit status $status, not 2"; exit 1; }
[ "$(wc -l <"$work/err.txt")" -eq 1 ] || { echo "FAIL: not one error line:"; cat "$work/err.txt"; exit 1; }
echo "installed runtime: relocatable, no offline-stage libraries, exit 2 on a missing bundle"
