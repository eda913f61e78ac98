#!/usr/bin/env bash
# CLI run of `levelsetd evolve` through the real binary: a unit sphere grows at speed 1 for
# t = 0.2 (radius 1.2 expected, checked through `measure --json`), shrinks under mean
# curvature flow (r^2 = 1 - 4t), writes its stats JSON; and the error paths.
# Args: LEVELSETD SCRATCH_DIR
set -euo pipefail
bin=$1; dir=$2
rm -rf "$dir"; mkdir -p "$dir"
checks=0
pass() { checks=$((checks + 1)); }
fail() { echo "cli_evolve: FAILED: $*" >&2; exit 1; }
py=/usr/bin/python3
radius() {  # radius of the sphere with the enclosed volume of the .lsg's zero level
  "$bin" measure "$1" --json | $py -c 'import json,sys,math; v=json.load(sys.stdin)["volume"]; print((3*v/(4*math.pi))**(1/3))'
}

"$bin" primitive sphere --resolution 48 -o "$dir/sphere.lsg" > /dev/null || fail "primitive"

"$bin" evolve "$dir/sphere.lsg" -o "$dir/grown.lsg" --speed constant --c 1 --time 0.2 \
  --scheme weno5 --rk 3 --stats "$dir/grow.json" > "$dir/grow.txt" || fail "evolve constant"
r=$(radius "$dir/grown.lsg")
$py -c "import sys; r=$r; sys.exit(0 if abs(r - 1.2) < 0.01 else 1)" || fail "grown radius $r, expected 1.2"
pass
$py - "$dir/grow.json" <<'PY' || fail "grow stats"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["op"] == "evolve", s
e = s
assert e["stop"] == "completed" and abs(e["time"] - 0.2) < 1e-12 and e["steps"] > 0, e
assert e["scheme"] == "weno5" and e["rk"] == 3, e
for k in ("operator", "tracking", "total"):
    assert s["seconds"][k] >= 0, s["seconds"]
PY
pass

"$bin" evolve "$dir/sphere.lsg" -o "$dir/shrunk.lsg" --speed mean-curvature --time 0.05 \
  --redistance-every 10 --report-every 50 > "$dir/shrink.txt" || fail "evolve mean-curvature"
grep -q '^step 50 ' "$dir/shrink.txt" || fail "no progress line every 50 steps"
r=$(radius "$dir/shrunk.lsg")
$py -c "import sys, math; r=$r; e=math.sqrt(1 - 4*0.05); sys.exit(0 if abs(r/e - 1) < 0.01 else 1)" \
  || fail "mean curvature flow radius $r, expected $($py -c 'import math; print(math.sqrt(0.8))')"
pass

# A typed formula gives the same result as the built-in it spells out.
"$bin" evolve "$dir/sphere.lsg" -o "$dir/f1.lsg" --speed '1 - eps*H' --const eps=0.1 --steps 5 > /dev/null || fail "formula"
"$bin" evolve "$dir/sphere.lsg" -o "$dir/f2.lsg" --speed one-minus-eps-kappa --eps 0.1 --steps 5 > /dev/null || fail "built-in"
[ "$(radius "$dir/f1.lsg")" = "$(radius "$dir/f2.lsg")" ] || fail "formula and built-in differ"
pass

# Long runs with the defaults (issue 13): 100 mean-curvature steps of a sphere at R = 64 once
# grew the band 5x (drift 0.64); the band now stays within 1.5x of its start and the drift
# near the surface small. A sphere run past its vanishing time stops as 'vanished', empty.
"$bin" primitive sphere --resolution 64 --band 3 -o "$dir/s64.lsg" > /dev/null || fail "primitive R=64"
"$bin" evolve "$dir/s64.lsg" -o "$dir/mcf100.lsg" --speed '-(k1+k2)' --steps 100 --threads 1 \
  --stats "$dir/mcf100.json" > /dev/null || fail "evolve 100 mean-curvature steps"
$py - "$dir/mcf100.json" <<'PY' || fail "100 mean-curvature steps: band or drift"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["stop"] == "completed" and s["steps"] == 100, s
assert s["active_voxels"] <= 1.5 * 63582, s["active_voxels"]
assert s["grad_drift"] < 0.05, s["grad_drift"]
PY
pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/gone.lsg" --speed mean-curvature --steps 3000 \
  --stats "$dir/gone.json" > "$dir/gone.txt" || fail "evolve past vanishing"
$py - "$dir/gone.json" <<'PY' || fail "vanishing sphere: $(cat "$dir/gone.txt")"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["stop"] == "vanished" and s["steps"] < 3000 and s["active_voxels"] == 0, s
assert abs(s["time"] - 0.25) < 0.02, s["time"]
PY
grep -q "vanished after" "$dir/gone.txt" || fail "no vanishing message"
pass

# Errors: usage (exit 2) and typed errors (exit 1).
set +e
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed $'\xc3\xa9+1' --steps 3 2> "$dir/err0.txt"; code=$?
[ $code -eq 1 ] && grep -qF $'unexpected character \'\xc3\xa9\' (U+00E9)' "$dir/err0.txt" \
  && iconv -f UTF-8 -t UTF-8 "$dir/err0.txt" > /dev/null || fail "non-ASCII in a formula: exit $code, $(cat "$dir/err0.txt")"
pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed $'1\xff' --steps 3 2> "$dir/err0b.txt"; code=$?
[ $code -eq 1 ] && iconv -f UTF-8 -t UTF-8 "$dir/err0b.txt" > /dev/null || fail "invalid UTF-8 in a formula: exit $code"
pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed warp --steps 3 2> "$dir/err1.txt"; code=$?
[ $code -eq 1 ] && grep -q "unknown name 'warp'" "$dir/err1.txt" && grep -q '^  \^' "$dir/err1.txt" \
  || fail "unknown speed name: exit $code, $(cat "$dir/err1.txt")"; pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed '1 - eps*' --const eps=0.1 --steps 3 2> "$dir/err1b.txt"; code=$?
[ $code -eq 1 ] && grep -q "column 9" "$dir/err1b.txt" || fail "formula syntax error: exit $code"; pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed '1 - eps*H' --const eps --steps 3 2> "$dir/err1c.txt"; code=$?
[ $code -eq 1 ] && grep -q "NAME=VALUE" "$dir/err1c.txt" || fail "bad --const: exit $code"; pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed constant 2> "$dir/err2.txt"; code=$?
[ $code -eq 2 ] && grep -q -- "--steps N or --time T" "$dir/err2.txt" || fail "missing steps/time exit $code"; pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed constant --steps 2 --time 1 2> "$dir/err3.txt"; code=$?
[ $code -eq 2 ] || fail "steps and time together exit $code"; pass
"$bin" evolve "$dir/missing.lsg" -o "$dir/x.lsg" --speed constant --steps 2 2> "$dir/err4.txt"; code=$?
[ $code -eq 1 ] && [ "$(wc -l < "$dir/err4.txt")" -eq 1 ] || fail "missing input exit $code"; pass
"$bin" evolve "$dir/sphere.lsg" -o "$dir/x.lsg" --speed constant --steps 2 --cfl 3 2> "$dir/err5.txt"; code=$?
[ $code -eq 2 ] || fail "cfl 3 exit $code"; pass
set -e
echo "cli_evolve: $checks checks passed"
