#!/usr/bin/env bash
# Builds the libFuzzer targets (Clang 14, ASan+UBSan, -DSPECULUM_FUZZ=ON) and runs each one in
# turn for a fixed time from its corpus in tests/fuzz/corpus/<target>/. Any crash, sanitizer
# report, leak, input slower than 1 s or escaped exception stops with a non-zero status; the
# reproducer is left in BUILD/artifacts/<target>/ (keep it under tests/fuzz/crashes/<target>/,
# where the ordinary test suite replays it). New inputs found go to BUILD/new-corpus/<target>/,
# never into the source tree.
#
#   tests/fuzz/run_short.sh [--seconds N | --runs N] [--targets a,b] [--build DIR] [--nice N] [--timeout S]
#   tests/fuzz/run_short.sh --merge SEEDS   # minimize SEEDS/<target> + the corpus into the corpus
#
# --seconds: per target (default 30; FUZZ_SECONDS too). --runs N: instead, exactly N inputs per
# target from a fixed seed (-seed=1), so a run gives the same result on any machine: what CI
# uses, since a time-limited run explores further on a faster machine. --targets: default all nine.
# --timeout: seconds (wall clock) after which one input counts as a hang: 1 with --seconds, 5
# with --runs; raise it for a long run at a low priority on a busy machine, where an input
# waits for the CPU, and replay the summary's slowest inputs on an idle one.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds="${FUZZ_SECONDS:-30}"
build=build-fuzz
targets="gltf,glb,obj,ply,off,stl,ray_file,image,scene_spec"
merge=""
runs=""
nice_level=0
timeout=""
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --runs) runs="$2"; shift 2 ;;
    --targets) targets="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    --merge) merge="$2"; shift 2 ;;
    --nice) nice_level="$2"; shift 2 ;;
    --timeout) timeout="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "run_short.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$seconds" in ''|*[!0-9]*) echo "run_short.sh: --seconds expects a whole number, got '$seconds'" >&2; exit 2 ;; esac
case "$runs" in *[!0-9]*) echo "run_short.sh: --runs expects a whole number, got '$runs'" >&2; exit 2 ;; esac
case "$timeout" in *[!0-9]*) echo "run_short.sh: --timeout expects a whole number, got '$timeout'" >&2; exit 2 ;; esac
# A fixed run also allows 5 s per input instead of 1 s: the same inputs on a slower or busier
# machine must not turn into a false "hang".
if [ -n "$runs" ]; then limit=(-seed=1 -runs="$runs" -timeout="${timeout:-5}"); else limit=(-max_total_time="$seconds" -timeout="${timeout:-1}"); fi

export CC="${FUZZ_CC:-clang-14}" CXX="${FUZZ_CXX:-clang++-14}"
IFS=, read -r -a list <<< "$targets"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSPECULUM_FUZZ=ON \
  -DSPECULUM_BUILD_TESTS=OFF -DSPECULUM_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build "$build" --target $(printf 'fuzz_%s ' "${list[@]}")

corpus=tests/fuzz/corpus
# Leaks inside the uninstrumented Debian libraries, each with its proof in the file.
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
# Inputs are small files; 64 KiB keeps each run fast while reaching every header path.
common=(-rss_limit_mb=2048 -max_len=65536 -print_final_stats=1)
status=0
# BUILD/fuzz-summary.txt: one row per target, from the latest run of each (CI runs the image
# target in a second call; its row joins the others').
summary="$build/fuzz-summary.txt"
if [ -f "$summary" ] && [ -z "$merge" ]; then
  grep -v -E "^($(IFS='|'; echo "${list[*]}")) " "$summary" > "$summary.tmp" || true
  mv "$summary.tmp" "$summary"
else
  printf '%-11s %12s %8s %8s %s\n' target executions seconds slowest result > "$summary"
fi
for t in "${list[@]}"; do
  bin="$build/tests/fuzz/fuzz_$t"
  if [ -n "$merge" ]; then
    fresh="$build/merge/$t"
    rm -rf "$fresh" && mkdir -p "$fresh" "$corpus/$t"
    "$bin" -merge=1 "${common[@]}" "$fresh" "$corpus/$t" "$merge/$t" 2>&1 | tail -n 2
    rm -f "$corpus/$t"/* && cp "$fresh"/* "$corpus/$t"/
    echo "$t: $(ls "$corpus/$t" | wc -l) files in the minimized corpus"
    continue
  fi
  mkdir -p "$build/new-corpus/$t" "$build/artifacts/$t"
  log="$build/fuzz-$t.log"
  start=$(date +%s)
  set +e
  nice -n "$nice_level" "$bin" "${common[@]}" "${limit[@]}" \
    -artifact_prefix="$build/artifacts/$t/" "$build/new-corpus/$t" "$corpus/$t" > "$log" 2>&1
  rc=$?
  set -e
  executed=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  slowest=$(sed -n 's/^stat::slowest_unit_time_sec: *//p' "$log" | tail -n 1)
  result=ok
  if [ "$rc" != 0 ]; then
    result="FAILED (exit $rc): $(grep -m1 -E '==[0-9]+== ?ERROR|runtime error|terminate called' "$log" || tail -n 1 "$log")"
    status=1
  fi
  printf '%-11s %12s %8s %8s %s\n' "$t" "${executed:-?}" "$(( $(date +%s) - start ))" "${slowest:-?}" "$result" | tee -a "$summary"
done
[ -n "$merge" ] && exit 0
if [ "$status" != 0 ]; then
  echo "fuzzing found a problem: logs in $build/fuzz-<target>.log, reproducers in $build/artifacts/" >&2
fi
exit "$status"
