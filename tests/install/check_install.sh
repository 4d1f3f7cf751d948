#!/usr/bin/env bash
# check_install.sh BUILD_DIR VERSION: installs the build into a fresh prefix, then builds and
# runs tests/install/consumer against it twice: as a CMake project of its own
# (find_package(dhcal CONFIG), dhcal::dhcal, and dhcal::io for fit_files.c, which loads the
# example's model file and CSV and fits) and with pkg-config (dhcal.pc). Nothing of the
# dhcal tree is on either include path: only the installed files.
set -euo pipefail
build=$1
version=$2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
for f in include/dhcal/dhcal.h include/dhcal/dhc_version.h; do
  [ -f "$prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done
# Every public header is reachable from dhcal.h, and every one that declares functions
# declares them extern "C" for C++ hosts.
for h in "$prefix"/include/dhcal/*.h; do
  name=$(basename "$h")
  case $name in dhcal.h) continue ;; esac
  grep -q "#include \"$name\"" "$prefix/include/dhcal/dhcal.h" ||
    { echo "FAIL: dhcal.h does not include $name"; exit 1; }
  case $name in dhc_config.h | dhc_version.h) continue ;; esac
  # no function declared (a line opening with a return type and a name): includes, macros
  grep -qE '^[A-Za-z_][A-Za-z_0-9 *]* \**[a-z_0-9]+\(' "$h" || continue
  grep -q 'extern "C"' "$h" || { echo "FAIL: $name has no extern \"C\" block"; exit 1; }
done
lib=$(find "$prefix" -name libdhcal.a | head -1)
[ -n "$lib" ] || { echo "FAIL: libdhcal.a not installed"; exit 1; }
echo "installed: ${lib#"$prefix"/}"
got=$("$prefix/bin/dhcal" --version)
[ "$got" = "dhcal $version" ] || { echo "FAIL: installed dhcal --version says '$got'"; exit 1; }
echo "installed: bin/dhcal ($got)"

echo "--- find_package(dhcal CONFIG)"
cmake -S "$here/consumer" -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$prefix" -DDHCAL_EXPECTED_VERSION="$version" >"$work/configure.log" \
  || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" >"$work/build.log" || { cat "$work/build.log"; exit 1; }
"$work/consumer/consumer"
# dhcal::io: the model file and measurements of the example, loaded and fitted
examples=$(cd "$here/../../examples/data/compliance" && pwd)
"$work/consumer/fit_files" "$examples/model.json" "$examples/train.csv" |
  tee "$work/fit_files.log"
grep -qE 'RMS [0-9.]+ mm, ok' "$work/fit_files.log" ||
  { echo "FAIL: fit_files did not fit the example"; exit 1; }
[ -f "$prefix/include/dhcal_io/dhcal_io.h" ] || { echo "FAIL: dhcal_io headers not installed"; exit 1; }

echo "--- pkg-config --cflags --libs dhcal"
pcdir=$(dirname "$(find "$prefix" -name dhcal.pc | head -1)")
got=$(PKG_CONFIG_PATH=$pcdir pkg-config --modversion dhcal)
[ "$got" = "$version" ] || { echo "FAIL: pkg-config says version $got, the tree $version"; exit 1; }
# shellcheck disable=SC2046 # the flags are words
c++ -std=c++17 -Wall -Wextra -Werror -pedantic -DEXPECTED_VERSION="\"$version\"" \
    "$here/consumer/consumer.cpp" -o "$work/consumer-pc" \
    $(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs dhcal)
"$work/consumer-pc"
