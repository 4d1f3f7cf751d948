# scripts/prereq.sh: sourced by scripts/demo, scripts/test and bench/run. Never run alone.
#
#   prereq_ensure WHO NEED...
#     installs the packages scripts/packages lists for the needs that dpkg does not have
#     (apt-get on Debian as root; otherwise it names them and fails), then proves each
#     need's toolchain: a small program compiled, linked and run the way the preset will
#     (the Cortex-M4 one on qemu-system-arm, the aarch64 one under qemu-aarch64). A need
#     whose probe fails names its packages and fails, installed or not: a compiler without
#     its target's C library is caught here, not in CMake's compiler check.
#   prereq_packages NEED...   the packages the needs list, one a line
#   prereq_scipy_python       the python3 that imports numpy and scipy (need bench)
#
# The needs are the names in scripts/packages: demo host static valgrind linux-port asan
# fuzz cortex-m4 aarch64-linux bench python.

prereq_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
prereq_list=$prereq_root/scripts/packages
prereq_apt_updated=0

prereq_packages() {
  awk -v needs=" $* " '
    /^[[:space:]]*(#|$)/ { next }
    { for (i = 2; i <= NF; ++i) if (index(needs, " " $i " ")) { print $1; next } }
  ' "$prereq_list" | sort -u
}

# The packages of $@ that dpkg does not list as installed. Without dpkg nothing is known to
# be missing: the probes decide.
prereq_not_installed() {
  command -v dpkg-query >/dev/null 2>&1 || return 0
  local p
  for p in "$@"; do
    dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q '^install ok installed$' ||
      echo "$p"
  done
}

prereq_apt_install() {
  local who=$1
  shift
  if [ "$(id -u)" -ne 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "$who: FAILED: missing Debian packages: $*" >&2
    echo "  install them: sudo apt-get install --no-install-recommends $*" >&2
    return 1
  fi
  echo "$who: installing $*"
  local log
  log=$(mktemp)
  export DEBIAN_FRONTEND=noninteractive
  if [ "$prereq_apt_updated" = 0 ]; then
    apt-get update -qq >"$log" 2>&1 || { cat "$log" >&2; rm -f "$log"; return 1; }
    prereq_apt_updated=1
  fi
  if ! apt-get install -y -qq --no-install-recommends "$@" >"$log" 2>&1; then
    tail -20 "$log" >&2
    rm -f "$log"
    echo "$who: FAILED: apt-get could not install: $*" >&2
    return 1
  fi
  rm -f "$log"
}

# ---------------------------------------------------------------- probes
# Each runs in a scratch directory and prints why it failed.

prereq_c_source='#include <math.h>
#include <string.h>
int main(void)
{
    volatile double x = 2.0;
    char a[8];
    const char b[8] = "dhcal";
    memcpy(a, b, sizeof a);
    return sqrt(x * x) == 2.0 && strcmp(a, "dhcal") == 0 ? 0 : 1;
}'

prereq_fail() {
  echo "  probe: $*" >&2
  return 1
}

prereq_cmd() {
  command -v "$1" >/dev/null 2>&1 || prereq_fail "no '$1' on PATH"
}

probe_build_tools() {
  prereq_cmd cmake && prereq_cmd ninja || return 1
  local v
  v=$(cmake --version | awk 'NR == 1 {print $3}')
  [ "$(printf '3.25\n%s\n' "$v" | sort -V | head -1)" = 3.25 ] ||
    prereq_fail "cmake $v found, CMakePresets.json needs >= 3.25"
}

# gcc compiles, links against libc and libm, and the program runs; then cJSON the same way.
probe_host_c() {
  prereq_cmd gcc || return 1
  printf '%s\n' "$prereq_c_source" >c.c
  gcc -std=c11 -o c c.c -lm >log 2>&1 || prereq_fail "gcc cannot link C: $(tail -3 log)" ||
    return 1
  ./c || prereq_fail "gcc's program did not run"
}

probe_cjson() {
  printf '%s\n' '#include <cjson/cJSON.h>' \
    'int main(void) { cJSON *j = cJSON_Parse("[1]"); int ok = cJSON_GetArraySize(j) == 1;' \
    '  cJSON_Delete(j); return ok ? 0 : 1; }' >j.c
  local flags
  flags=$(pkg-config --cflags --libs libcjson 2>/dev/null || echo -lcjson)
  # shellcheck disable=SC2086 # word splitting intended: compiler flags
  gcc -o j j.c $flags >log 2>&1 || prereq_fail "cannot link cJSON: $(tail -3 log)" ||
    return 1
  ./j || prereq_fail "cJSON's program did not run"
}

# libxml2 (dhcal import-urdf): compiled and linked through pkg-config as CMake finds it, and
# the program parses a document.
probe_libxml2() {
  printf '%s\n' '#include <libxml/parser.h>' \
    'int main(void) { xmlDoc *d = xmlReadMemory("<robot/>", 8, "p.xml", NULL, XML_PARSE_NONET);' \
    '  int ok = d != NULL && xmlDocGetRootElement(d) != NULL; xmlFreeDoc(d); return ok ? 0 : 1; }' >x.c
  local flags
  flags=$(pkg-config --cflags --libs libxml-2.0 2>/dev/null) ||
    prereq_fail "pkg-config finds no libxml-2.0" || return 1
  # shellcheck disable=SC2086 # word splitting intended: compiler flags
  gcc -o x x.c $flags >log 2>&1 || prereq_fail "cannot link libxml2: $(tail -3 log)" ||
    return 1
  ./x || prereq_fail "libxml2's program did not run"
}

probe_pip() {
  python3 -m pip --version >/dev/null 2>&1 || prereq_fail "no pip for python3 (Unity comes from PyPI)"
}

probe_demo() {
  probe_build_tools && probe_host_c && probe_cjson && probe_libxml2 && probe_pip
}

# The installed package is used from C++ (tests/install): g++ compiles, links and runs.
probe_host_cxx() {
  prereq_cmd c++ || return 1
  printf '%s\n' '#include <cmath>' '#include <string>' \
    'int main() { std::string s("dhcal"); return std::sqrt(4.0) == 2.0 && s.size() == 5 ? 0 : 1; }' >x.cpp
  c++ -std=c++17 -o x x.cpp >log 2>&1 || prereq_fail "c++ cannot link C++: $(tail -3 log)" ||
    return 1
  ./x || prereq_fail "c++'s program did not run"
}

probe_host() {
  probe_demo && probe_host_cxx
}

# The Python package (need python): the C build of probe_demo, and a virtual environment
# with pip made by the python3 the step uses (Debian's needs python3-venv for it).
probe_python() {
  probe_build_tools && probe_host_c && probe_cjson && probe_libxml2 || return 1
  python3 -m venv v >log 2>&1 ||
    prereq_fail "python3 -m venv cannot make a virtual environment: $(tail -3 log)" || return 1
  v/bin/python -m pip --version >log 2>&1 ||
    prereq_fail "the virtual environment has no pip: $(tail -3 log)"
}

probe_static() {
  clang-tidy --version >/dev/null 2>&1 || prereq_fail "clang-tidy does not run" || return 1
  cppcheck --version >/dev/null 2>&1 || prereq_fail "cppcheck does not run" || return 1
  printf 'int main(void){return 0;}\n' >fmt.c
  clang-format --style=LLVM fmt.c >/dev/null 2>&1 || prereq_fail "clang-format does not run"
}

probe_valgrind() {
  probe_host_c || return 1
  valgrind -q --error-exitcode=3 ./c >log 2>&1 ||
    prereq_fail "valgrind cannot run a program: $(tail -3 log)"
}

# libgpiod's 1.x API links; the VM test's host tools are there.
probe_linux_port() {
  probe_host_c || return 1
  printf '%s\n' '#include <gpiod.h>' \
    'int main(void) { int (*f)(struct gpiod_line *, const char *) = gpiod_line_request_both_edges_events;' \
    '  return f != 0 ? 0 : 1; }' >g.c
  local flags
  flags=$(pkg-config --cflags --libs 'libgpiod < 2' 2>/dev/null) ||
    prereq_fail "pkg-config finds no libgpiod 1.x" || return 1
  # shellcheck disable=SC2086 # word splitting intended: compiler flags
  gcc -o g g.c $flags >log 2>&1 || prereq_fail "cannot link libgpiod 1.x: $(tail -3 log)" ||
    return 1
  ./g || prereq_fail "libgpiod's program did not run" || return 1
  local c
  for c in qemu-system-x86_64 candump make xz python3 busybox; do
    prereq_cmd "$c" || return 1
  done
  ! ldd "$(command -v busybox)" >/dev/null 2>&1 || prereq_fail "busybox is not statically linked"
}

probe_asan() {
  probe_build_tools || return 1
  printf '%s\n' "$prereq_c_source" >c.c
  gcc -std=c11 -fsanitize=address,undefined -o a c.c -lm >log 2>&1 ||
    prereq_fail "gcc cannot link with ASan + UBSan: $(tail -3 log)" || return 1
  ./a || prereq_fail "the ASan + UBSan program did not run"
}

# Line coverage (need coverage): gcc's --coverage compiles, links and runs, leaving its
# counts (.gcda), and gcovr reads them.
probe_coverage() {
  probe_build_tools && probe_host_c && probe_cjson && probe_libxml2 || return 1
  prereq_cmd gcovr || return 1
  printf '%s\n' "$prereq_c_source" >c.c
  gcc -std=c11 --coverage -fprofile-update=atomic -o a c.c -lm >log 2>&1 ||
    prereq_fail "gcc cannot link with --coverage: $(tail -3 log)" || return 1
  ./a || prereq_fail "the --coverage program did not run" || return 1
  [ -f a-c.gcda ] || [ -f c.gcda ] || prereq_fail "the --coverage program left no counts" || return 1
  gcovr -r . --print-summary >log 2>&1 || prereq_fail "gcovr cannot read the counts: $(tail -3 log)"
}

probe_fuzz() {
  probe_build_tools && probe_cjson && probe_libxml2 || return 1
  prereq_cmd clang || return 1
  printf '%s\n' '#include <stddef.h>' '#include <stdint.h>' \
    'int LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }' >f.c
  clang -fsanitize=fuzzer,address,undefined -o f f.c >log 2>&1 ||
    prereq_fail "clang cannot link libFuzzer with ASan + UBSan: $(tail -3 log)" || return 1
  ./f -runs=10 >log 2>&1 || prereq_fail "the libFuzzer program did not run: $(tail -3 log)"
}

# A hard-float Cortex-M4 program that links newlib's libc and libm, run on QEMU's mps2-an386:
# it enables the FPU, computes, and leaves through semihosting SYS_EXIT with "application
# exit" (QEMU status 0) or a run-time error (status 1).
probe_cortex_m4() {
  # the host side of the twin programs (tests/target/twin) is built with the host's gcc
  probe_build_tools && probe_host_c || return 1
  prereq_cmd arm-none-eabi-gcc && prereq_cmd qemu-system-arm || return 1
  cat >m.c <<'EOF'
#include <math.h>
#include <stdint.h>
#include <string.h>
extern uint32_t probe_stack_top;
void probe_reset(void);
__attribute__((section(".vectors"), used))
static const void *const probe_vectors[2] = {&probe_stack_top, (const void *)probe_reset};
static void probe_exit(uint32_t reason)
{
    register uint32_t r0 __asm__("r0") = 0x18U;
    register uint32_t r1 __asm__("r1") = reason;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
}
void probe_reset(void)
{
    *(volatile uint32_t *)0xE000ED88U |= 0xFU << 20;
    __asm__ volatile("dsb\n\tisb");
    volatile double x = 2.0;
    char a[8];
    const char b[8] = "dhcal";
    memcpy(a, b, sizeof a);
    probe_exit(sqrt(x * x) == 2.0 && a[4] == 'l' ? 0x20026U : 0x20024U);
    for (;;) {
    }
}
EOF
  cat >m.ld <<'EOF'
MEMORY { CODE (rx) : ORIGIN = 0x00000000, LENGTH = 4M
         RAM (rwx) : ORIGIN = 0x20000000, LENGTH = 4M }
ENTRY(probe_reset)
SECTIONS {
  .text : { KEEP(*(.vectors)) *(.text .text.*) *(.rodata .rodata.*) } > CODE
  .ARM.exidx : { *(.ARM.exidx*) } > CODE
  .data : { *(.data .data.*) } > RAM
  .bss : { *(.bss .bss.*) *(COMMON) } > RAM
  probe_stack_top = ORIGIN(RAM) + LENGTH(RAM);
}
EOF
  arm-none-eabi-gcc -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O1 \
    -nostartfiles -T m.ld -o m.elf m.c -lm -lc >log 2>&1 ||
    prereq_fail "arm-none-eabi-gcc cannot link newlib for the hard-float Cortex-M4: $(tail -3 log)" ||
    return 1
  timeout 60 qemu-system-arm -M mps2-an386 -nographic -monitor none \
    -semihosting-config enable=on,target=native -kernel m.elf </dev/null >log 2>&1 ||
    prereq_fail "the Cortex-M4 program did not run on qemu-system-arm: $(tail -3 log)"
}

probe_aarch64_linux() {
  probe_build_tools || return 1
  prereq_cmd aarch64-linux-gnu-gcc && prereq_cmd qemu-aarch64 || return 1
  printf '%s\n' "$prereq_c_source" >c.c
  aarch64-linux-gnu-gcc -std=c11 -o c c.c -lm >log 2>&1 ||
    prereq_fail "aarch64-linux-gnu-gcc cannot link C: $(tail -3 log)" || return 1
  qemu-aarch64 -L /usr/aarch64-linux-gnu ./c >log 2>&1 ||
    prereq_fail "the aarch64 program did not run under qemu-aarch64: $(tail -3 log)"
}

# The interpreter that imports numpy and scipy: python3 on PATH, else Debian's own (a
# python3 of pyenv or a venv earlier on PATH does not see Debian's python3-scipy).
prereq_scipy_python() {
  local py
  for py in python3 /usr/bin/python3; do
    if "$py" -c 'import numpy, scipy' >/dev/null 2>&1; then
      command -v "$py"
      return 0
    fi
  done
  return 1
}

# The Ceres peer of bench/ceres: g++ compiles a hand-written cost function and a TinySolver
# functor against Debian's Ceres and Eigen, links libceres, and both solvers find x = 3.
probe_ceres() {
  prereq_cmd g++ || return 1
  cat >r.cc <<'EOF'
#include <ceres/ceres.h>
#include <ceres/tiny_solver.h>
#include <cmath>
struct Cost : ceres::SizedCostFunction<1, 1> {
  bool Evaluate(double const *const *x, double *r, double **j) const override {
    r[0] = x[0][0] - 3.0;
    if (j != nullptr && j[0] != nullptr) j[0][0] = 1.0;
    return true;
  }
};
struct Tiny {
  typedef double Scalar;
  enum { NUM_RESIDUALS = 1, NUM_PARAMETERS = 1 };
  bool operator()(const double *x, double *r, double *j) const {
    r[0] = x[0] - 3.0;
    if (j != nullptr) j[0] = 1.0;
    return true;
  }
};
int main() {
  double x = 0.0;
  ceres::Problem problem;
  problem.AddResidualBlock(new Cost, nullptr, &x);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  Eigen::Matrix<double, 1, 1> y(0.0);
  ceres::TinySolver<Tiny> tiny;
  tiny.Solve(Tiny(), &y);
  return std::fabs(x - 3.0) < 1e-6 && std::fabs(y(0) - 3.0) < 1e-6 ? 0 : 1;
}
EOF
  local flags
  flags=$(pkg-config --cflags eigen3 2>/dev/null) ||
    prereq_fail "pkg-config finds no eigen3 (Ceres' headers include Eigen)" || return 1
  # shellcheck disable=SC2086 # word splitting intended: compiler flags
  g++ -std=c++17 $flags -o r r.cc -lceres -lglog >log 2>&1 ||
    prereq_fail "g++ cannot link Ceres: $(tail -3 log)" || return 1
  ./r || prereq_fail "the Ceres program did not run or did not solve"
}

probe_bench() {
  probe_demo || return 1
  prereq_scipy_python >/dev/null || prereq_fail "no python3 here imports numpy and scipy" ||
    return 1
  [ -x /usr/bin/time ] || prereq_fail "no GNU time at /usr/bin/time (peak memory)" || return 1
  probe_ceres
}

prereq_probe() {
  local need=$1 dir rc=0
  dir=$(mktemp -d)
  (cd "$dir" && "probe_${need//-/_}") || rc=$?
  rm -rf "$dir"
  return "$rc"
}

# ---------------------------------------------------------------- the entry point
prereq_ensure() {
  local who=$1
  shift
  local need pkgs missing
  for need in "$@"; do
    grep -Eq "^[^#].*[[:space:]]$need([[:space:]]|\$)" "$prereq_list" ||
      { echo "$who: FAILED: scripts/packages names no need '$need'" >&2; return 1; }
  done
  pkgs=$(prereq_packages "$@")
  # shellcheck disable=SC2086 # word splitting intended: a package list
  missing=$(prereq_not_installed $pkgs | xargs)
  if [ -n "$missing" ]; then
    # shellcheck disable=SC2086
    prereq_apt_install "$who" $missing || return 1
  fi
  for need in "$@"; do
    if ! prereq_probe "$need"; then
      echo "$who: FAILED: the $need toolchain does not work; it needs the Debian packages:" \
        "$(prereq_packages "$need" | xargs)" >&2
      return 1
    fi
  done
}
