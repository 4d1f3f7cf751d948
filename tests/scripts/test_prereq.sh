#!/usr/bin/env bash
# test_prereq.sh: scripts/prereq.sh and scripts/packages, the set-up the two commands rely on.
#   - every need that scripts/test and scripts/demo ask for lists its packages, and has a
#     toolchain probe; the C runtimes the cross presets link with are listed (the fresh
#     machine of issue #11 had the cross compiler without libc6-dev-arm64-cross);
#   - a package that dpkg does not have, on a machine where apt-get cannot run (not root),
#     is named with the install command, and prereq_ensure fails;
#   - a toolchain whose probe fails names the need's packages and fails, although dpkg
#     says every package is installed;
#   - scripts/demo asks for need `demo` only, which lists no cross or analysis package.
# Runs without network or root: dpkg-query, id and the compilers are stubbed on PATH.
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
failures=0
checks=0
check() {
  checks=$((checks + 1))
  if ! eval "$2"; then
    echo "FAIL: $1"
    failures=$((failures + 1))
  fi
}

# shellcheck source=scripts/prereq.sh
. "$root/scripts/prereq.sh"

has() { prereq_packages "$1" | grep -qx "$2"; }
check "aarch64-linux lists the arm64 C library" 'has aarch64-linux libc6-dev-arm64-cross'
check "aarch64-linux lists the cross gcc" 'has aarch64-linux gcc-aarch64-linux-gnu'
check "aarch64-linux lists qemu-user" 'has aarch64-linux qemu-user'
check "cortex-m4 lists newlib" 'has cortex-m4 libnewlib-arm-none-eabi'
check "cortex-m4 lists qemu-system-arm" 'has cortex-m4 qemu-system-arm'
check "fuzz lists the libFuzzer runtime" 'has fuzz libclang-rt-dev'
check "demo lists cJSON" 'has demo libcjson-dev'
check "demo lists libxml2" 'has demo libxml2-dev'
check "demo lists the host C library" 'has demo libc6-dev'
check "linux-port lists libgpiod" 'has linux-port libgpiod-dev'
check "python lists the venv module" 'has python python3-venv'
check "python lists cJSON (the package builds io/)" 'has python libcjson-dev'
check "demo needs no cross or analysis package" \
  '! prereq_packages demo | grep -Eq "arm|aarch64|clang|qemu|valgrind|cppcheck|gpiod"'

# Every need named in the list, and every need the scripts ask for, has a probe.
needs=$(awk '!/^[[:space:]]*(#|$)/ { for (i = 2; i <= NF; ++i) print $i }' \
          "$root/scripts/packages" | sort -u)
for n in $needs demo host static valgrind linux-port asan fuzz cortex-m4 aarch64-linux bench python; do
  check "need $n has a probe" "declare -F probe_${n//-/_} >/dev/null"
  check "need $n lists packages" "[ -n \"\$(prereq_packages $n)\" ]"
done
check "scripts/demo asks for need demo" "grep -q 'prereq_ensure scripts/demo demo' '$root/scripts/demo'"
check "scripts/test's presets ask for their needs" \
  "grep -q '\\[aarch64-linux\\]=aarch64-linux' '$root/scripts/test'"

# Stubs: dpkg knows nothing installed but what $STUB_INSTALLED lists; not root.
stub=$(mktemp -d)
trap 'rm -rf "$stub"' EXIT
cat >"$stub/dpkg-query" <<'EOF'
#!/bin/sh
eval "pkg=\${$#}"
for p in $STUB_INSTALLED; do
  [ "$p" = "$pkg" ] && { echo "install ok installed"; exit 0; }
done
exit 1
EOF
printf '#!/bin/sh\necho 1000\n' >"$stub/id"
chmod +x "$stub/dpkg-query" "$stub/id"

out=$(PATH="$stub:$PATH" STUB_INSTALLED="gcc-aarch64-linux-gnu qemu-user cmake ninja-build" \
      prereq_ensure test aarch64-linux 2>&1)
rc=$?
check "missing packages without root: fails" "[ $rc -ne 0 ]"
check "missing packages without root: names libc6-dev-arm64-cross" \
  "printf '%s' \"\$out\" | grep -q 'missing Debian packages:.*libc6-dev-arm64-cross'"
check "missing packages without root: gives the install command" \
  "printf '%s' \"\$out\" | grep -q 'apt-get install --no-install-recommends'"
check "missing packages without root: does not name what is installed" \
  "! printf '%s' \"\$out\" | grep -q 'missing Debian packages:.*qemu-user'"

# dpkg says all is there, but the cross compiler cannot link: the probe names the packages.
cat >"$stub/aarch64-linux-gnu-gcc" <<'EOF'
#!/bin/sh
echo "/usr/bin/aarch64-linux-gnu-ld: cannot find Scrt1.o: No such file or directory" >&2
exit 1
EOF
printf '#!/bin/sh\nexit 0\n' >"$stub/qemu-aarch64"
chmod +x "$stub/aarch64-linux-gnu-gcc" "$stub/qemu-aarch64"
all=$(prereq_packages aarch64-linux | xargs)
out=$(PATH="$stub:$PATH" STUB_INSTALLED="$all" prereq_ensure test aarch64-linux 2>&1)
rc=$?
check "a toolchain that cannot link: fails" "[ $rc -ne 0 ]"
check "a toolchain that cannot link: says why" "printf '%s' \"\$out\" | grep -q 'cannot find Scrt1.o'"
check "a toolchain that cannot link: names the packages" \
  "printf '%s' \"\$out\" | grep -q 'needs the Debian packages:.*libc6-dev-arm64-cross'"
check "an unknown need fails" "! prereq_ensure test no-such-need 2>/dev/null"

echo "$((checks - failures)) passed, $failures failed"
[ "$failures" -eq 0 ]
