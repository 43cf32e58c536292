#!/usr/bin/env bash
# CI's sanitizer steps, each in its own build folder:
#   asan  the whole project and every test under AddressSanitizer and
#         UndefinedBehaviorSanitizer (gcc; build-asan), the whole ctest suite;
#   tsan  the tests of the multi-threaded paths under ThreadSanitizer (gcc;
#         build-tsan): the servers, the dispatcher, the CLI's ingest stream,
#         the thread pool and what runs on it, i.e. the cases labelled
#         `threads` (meshseek_add_test's THREADED), and only what they need
#         is compiled (the `threaded_tests` target);
#   fuzz  the libFuzzer harnesses (clang; build-fuzz), each for a short run
#         over its seed corpus (FUZZ_SECONDS, default 20).
#
#   scripts/sanitize.sh            # all three, in this order
#   scripts/sanitize.sh tsan fuzz  # some of them
#
# Timeouts are each test's release timeout times 3 (ASan) or 4 (TSan), and
# the tests use smaller data under a sanitizer (common/base/test_env.h). The
# tests' own sources compile at -O0 and protoc's generated code without
# instrumentation (cmake/meshseek.cmake says why).
#
# The services tests start the servers as child processes whose output goes
# to log files, and kill them with SIGKILL; a sanitizer report there would not
# fail a test. Every process therefore writes its reports to
# <build>/sanitizer-reports/ (log_path), and a step fails when any report is
# there. Suppressions (scripts/sanitizers/) are for third-party code only.
set -euo pipefail
cd "$(dirname "$0")/.."
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$PWD}
JOBS=${JOBS:-$(nproc)}
STEPS=${*:-asan tsan fuzz}
SUPP=$PWD/scripts/sanitizers

summary=()
step_start=0
begin() {
  step_start=$(date +%s)
  echo "=== sanitize: $1"
}
end() {
  summary+=("$(printf '%-5s %4d s  %s' "$1" $(($(date +%s) - step_start)) "$2")")
  echo "=== sanitize: ${summary[-1]}"
}

# Configures $1 (once) with compiler $2, compile flags $3, link flags $4, the
# factor $5 on every test's timeout (MESHSEEK_TEST_TIMEOUT_SCALE) and the
# optimisation level $6 of the code under test. ASan + UBSan use -O1: gcc
# takes 0.6 of -O2's time over instrumented code (point_graph.cc 35 s against
# 59 s), the build was most of the step, and the tests ran no slower (359 s
# against 371 s). TSan keeps -O2: at -O1 its build took 330 s instead of 431
# but its tests 369 s instead of 258 (the end-to-end pipeline case 144 s
# instead of 82, 60 % of its timeout).
configure() {
  local dir=$1 cxx=$2 flags=$3 link=$4 scale=$5 opt=$6
  if [ ! -f "$dir/build.ninja" ]; then
    cmake -S . -B "$dir" -G Ninja -DCMAKE_CXX_COMPILER="$cxx" \
      -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$opt -g1" \
      -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$link" \
      -DMESHSEEK_BUILD_BENCHMARKS=OFF -DMESHSEEK_TEST_TIMEOUT_SCALE="$scale" \
      -DMESHSEEK_TEST_COMPILE_OPTIONS=-O0 -DMESHSEEK_GENERATED_COMPILE_OPTIONS=-fno-sanitize=all
  fi
}

# Runs ctest in $1 with the remaining arguments, its reports in $1's
# sanitizer-reports/, then prints each test's time against its timeout.
run_ctest() {
  local dir=$1
  shift
  local reports=$PWD/$dir/sanitizer-reports
  rm -rf "$reports" && mkdir -p "$reports/tmp"
  rc=0
  # The test processes keep their folders (servers' logs) for check_reports.
  TEST_TMPDIR=$reports/tmp MESHSEEK_KEEP_TEST_TMPDIR=1 \
    ctest --test-dir "$dir" --output-on-failure -j"$JOBS" --output-junit "$PWD/$dir/junit.xml" \
      "$@" || rc=$?
  python3 scripts/test_times.py "$dir" "$dir/junit.xml" || true
  check_reports "$reports" || rc=1
  [ "$rc" -eq 0 ] || exit "$rc"
}

# Fails when any process of the run left a sanitizer report in $1: a
# log_path file of ASan/LSan/TSan, or a report in a server's log under
# $1/tmp (gcc's UBSan ignores log_path and writes to stderr, which the
# services tests send to <TEST_TMPDIR>/<role>-<port>.log).
check_reports() {
  local reports
  reports=$( (find "$1" -maxdepth 1 -type f
              grep -rlE 'runtime error:|ERROR: (Address|Leak)Sanitizer|WARNING: ThreadSanitizer' \
                "$1/tmp" 2>/dev/null) | sort -u)
  if [ -n "$reports" ]; then
    for r in $reports; do
      echo "--- $r"
      grep -m1 -A60 -E 'runtime error:|Sanitizer' "$r" || head -60 "$r"
    done
    echo "sanitize: $(echo "$reports" | wc -l) file(s) with sanitizer reports in $1" >&2
    return 1
  fi
}

for step in $STEPS; do
  case $step in
    asan)
      begin "ASan + UBSan: whole project, whole test suite (build-asan)"
      flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
      configure build-asan g++ "$flags" "$flags" 3 -O1
      cmake --build build-asan -- -j"$JOBS"
      ASAN_OPTIONS="log_path=$PWD/build-asan/sanitizer-reports/asan:detect_leaks=1:strict_string_checks=1:check_initialization_order=1" \
      LSAN_OPTIONS="suppressions=$SUPP/lsan.supp:print_suppressions=0" \
      UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
        run_ctest build-asan
      end asan "ctest, every test"
      ;;
    tsan)
      begin "TSan: the tests of the multi-threaded paths (build-tsan)"
      # Every TSan executable links the absl::Mutex annotations first, so that
      # its Mutex entry points win over Debian's uninstrumented ones
      # (scripts/sanitizers/absl_mutex_tsan.cc says why).
      mkdir -p build-tsan
      shim=$PWD/build-tsan/libabsl_mutex_tsan.so
      if [ ! -f "$shim" ] || [ "$SUPP/absl_mutex_tsan.cc" -nt "$shim" ]; then
        g++ -std=c++17 -shared -fPIC -O1 -fsanitize=thread -o "$shim" "$SUPP/absl_mutex_tsan.cc" \
          -labsl_synchronization -ldl
      fi
      configure build-tsan g++ "-fsanitize=thread -fno-omit-frame-pointer" \
        "-fsanitize=thread -Wl,--no-as-needed $shim -Wl,--as-needed" 4 -O2
      cmake --build build-tsan --target threaded_tests -- -j"$JOBS"
      TSAN_OPTIONS="log_path=$PWD/build-tsan/sanitizer-reports/tsan:suppressions=$SUPP/tsan.supp:halt_on_error=0:second_deadlock_stack=1" \
        run_ctest build-tsan -L '^threads$'
      end tsan "ctest -L threads"
      ;;
    fuzz)
      begin "libFuzzer: every harness for ${FUZZ_SECONDS:-20} s (build-fuzz)"
      if [ ! -f build-fuzz/build.ninja ]; then
        cmake -S . -B build-fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DMESHSEEK_FUZZ=ON \
          -DMESHSEEK_BUILD_TESTS=OFF -DMESHSEEK_BUILD_BENCHMARKS=OFF \
          -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only"
      fi
      cmake --build build-fuzz --target fuzzers -- -j"$JOBS"
      tests/fuzz/run.sh build-fuzz -max_total_time="${FUZZ_SECONDS:-20}"
      end fuzz "each harness ${FUZZ_SECONDS:-20} s"
      ;;
    *)
      echo "sanitize: unknown step '$step' (asan, tsan or fuzz)" >&2
      exit 2
      ;;
  esac
done
printf 'sanitize: %s\n' "${summary[@]}"
