#!/usr/bin/env bash
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ and runs
# the whole CTest suite there (unit, integration, browser: the tests spawn the sanitized binaries).
# Any sanitizer report fails the test that caused it: ASan and UBSan stop the process with a
# non-zero status, LeakSanitizer reports leaks at exit. Suppressions (third-party code only, one
# reason per line): deploy/sanitizers/lsan.supp. Extra arguments go to ctest (e.g. -R store).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build-asan"
"$root/deploy/bootstrap.sh"
start=$(date +%s)
# Warnings are errors here too (this is the only build of the tests); CMakeLists.txt drops GCC's
# one warning that is wrong on instrumented code. -O1 -g1: the sanitizers' usual level, half the
# compile time of -O2 -g, and reports keep file:line.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTELLTALE_SANITIZE=ON \
  -DTELLTALE_WERROR=ON -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DTELLTALE_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)"
"$root/deploy/web_deps.sh" || echo "test_sanitized: web/ npm packages not installed" >&2
built=$(date +%s)
# Exported, so every process a test starts (shore_server, boat_node, ...) inherits them.
# new_delete_type_mismatch=0: Fast DDS 2.9.1 itself deletes its StatisticsWriterImpl writers
# through a base of the wrong size (RTPSWriter::~RTPSWriter, seen on every participant shutdown);
# ASan cannot suppress that per library. Our code is covered by -Wnon-virtual-dtor -Werror.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1:check_initialization_order=1:new_delete_type_mismatch=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:report_error_type=1"
export LSAN_OPTIONS="suppressions=$root/deploy/sanitizers/lsan.supp:print_suppressions=0"
cd "$build"
status=0
# One more test at a time than cores: the longest tests mostly wait (the 5-minute link cut holds
# its slot for 312 s at a few % of a core, the crash cycles and backfill tests wait on restarts
# and timeouts), and with -j(nproc) they left one core idle for minutes.
ctest --output-on-failure -j"$(($(nproc) + 1))" --timeout 900 "$@" || status=$?
done_s=$(date +%s)
echo "test_sanitized: build $((built - start)) s, tests $((done_s - built)) s, status $status"
exit $status
