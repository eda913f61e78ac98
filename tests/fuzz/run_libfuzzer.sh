#!/usr/bin/env bash
# Builds one fuzz target as a real libFuzzer binary (clang, -fsanitize=fuzzer,address,undefined)
# in build/fuzz and runs it for SECONDS seconds over a copy of its seed corpus
# (tests/fuzz/corpus/TARGET, which is never modified). No network.
#
# Usage: tests/fuzz/run_libfuzzer.sh TARGET SECONDS
#   e.g. tests/fuzz/run_libfuzzer.sh fuzz_formula 60
# Exits 0 when the run ends with no finding; non-zero on any crash, sanitizer report, leak,
# timeout (one input over 10 s) or out-of-memory. Reproducers are kept in
# build/fuzz/findings/TARGET/ (replay one: build/fuzz/tests/fuzz/TARGET FILE).
# Environment: FUZZ_CC / FUZZ_CXX (default clang-14 / clang++-14, else clang / clang++),
#   FUZZ_JOBS (build parallelism, default nproc), FUZZ_BUILD_DIR (default build/fuzz).
set -euo pipefail

if [ $# -ne 2 ] || ! [[ $2 =~ ^[0-9]+$ ]] || [ "$2" -lt 1 ]; then
  echo "usage: $0 TARGET SECONDS" >&2
  exit 2
fi
target=$1
seconds=$2

root=$(cd "$(dirname "$0")/../.." && pwd)
build=${FUZZ_BUILD_DIR:-$root/build/fuzz}
seeds=$root/tests/fuzz/corpus/$target
if [ ! -d "$seeds" ]; then
  echo "run_libfuzzer: no seed corpus $seeds" >&2
  exit 2
fi

pick() { for c in "$@"; do command -v "$c" >/dev/null 2>&1 && { echo "$c"; return; }; done; }
cc=${FUZZ_CC:-$(pick clang-14 clang)}
cxx=${FUZZ_CXX:-$(pick clang++-14 clang++)}
if [ -z "$cc" ] || [ -z "$cxx" ]; then
  echo "run_libfuzzer: clang not found (deploy/install-deps.sh installs clang-14 and" \
       "libclang-rt-14-dev)" >&2
  exit 2
fi

# Configure once (only the fuzz targets are built from this tree; ccache is picked up by the
# top-level CMakeLists when present).
start=$(date +%s)
cmake -S "$root" -B "$build" -G Ninja \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
  -DLEVELSET_LIBFUZZER=ON -DLEVELSET_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" --target "$target" -j "${FUZZ_JOBS:-$(nproc)}"
binary=$build/tests/fuzz/$target
echo "run_libfuzzer: built $target in $(( $(date +%s) - start )) s"

# Work on a copy of the seeds: libFuzzer adds the inputs it finds interesting to the first
# corpus directory.
work=$build/runs/$target
findings=$build/findings/$target
rm -rf "$work"
mkdir -p "$work/corpus" "$findings"
cp -R "$seeds"/. "$work/corpus/"
find "$findings" -type f -delete

args=()
if [ "$target" = fuzz_formula ]; then
  # The language's tokens: mutations that insert whole names and operators go further.
  cat >"$work/formula.dict" <<'EOF'
"+"
"-"
"*"
"/"
"^"
"!"
"<"
"<="
">"
">="
"=="
"!="
"&&"
"||"
"?"
":"
"("
")"
","
"1e-3"
"2.5"
"1e308"
"1e-320"
"0"
"abs("
"sign("
"sqrt("
"cbrt("
"exp("
"log("
"sin("
"cos("
"tan("
"asin("
"acos("
"atan("
"floor("
"ceil("
"atan2("
"pow("
"min("
"max("
"step("
"clamp("
"smoothstep("
"pi"
"eps"
"c"
"d"
"x"
"y"
"z"
"nx"
"ny"
"nz"
"H"
"K"
"k1"
"k2"
"grad"
"t"
"h"
"kavg"
"dist"
"dgx"
"dgy"
"dgz"
"dn"
"img"
"edge"
"roi"
EOF
  args+=("-dict=$work/formula.dict")
fi

export ASAN_OPTIONS=${ASAN_OPTIONS:-abort_on_error=1:detect_leaks=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# The full log goes to log.txt; the terminal gets it without the NEW/REDUCE lines.
set +e
"$binary" "$work/corpus" \
  -max_total_time="$seconds" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$findings/" -print_final_stats=1 "${args[@]}" \
  2>&1 | tee "$work/log.txt" | grep -v -E '^#[0-9]+[[:space:]]+(NEW|REDUCE)'
status=${PIPESTATUS[0]}
set -e

if [ "$status" -ne 0 ] || [ -n "$(ls -A "$findings")" ]; then
  echo "run_libfuzzer: $target FAILED (exit $status); log $work/log.txt, reproducers:" >&2
  ls -l "$findings" >&2 || true
  exit 1
fi
echo "run_libfuzzer: $target ran ${seconds} s with no findings" \
     "($(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$work/log.txt" | grep -oE '[0-9]+$') runs," \
     "$(find "$work/corpus" -type f | wc -l) corpus files)"
