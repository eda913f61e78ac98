# Shared harness of the CLI scripts: source it after setting BIN, DIR, PY and CLI_TEST (the
# script's name in messages). run_ok / run_fail run the real levelsetd; a failed run_fail or
# soft_fail is counted and the remaining checks still run; cli_finish reports and exits.
checks=0
failures=0
fail() {
  echo "$CLI_TEST: FAILED: $*" >&2
  exit 1
}
# A failed error-path check is reported, and the remaining checks still run.
soft_fail() {
  echo "$CLI_TEST: FAILED: $*" >&2
  failures=$((failures + 1))
}
pass() { checks=$((checks + 1)); }
expect_absent() {
  if [[ -e $1 ]]; then soft_fail "$2"; else pass; fi
}

# run_ok NAME ARGS...: must exit 0; stdout in $DIR/NAME.out, stderr in $DIR/NAME.err.
run_ok() {
  local name=$1
  shift
  local rc=0
  "$BIN" "$@" >"$DIR/$name.out" 2>"$DIR/$name.err" || rc=$?
  if [[ $rc -ne 0 ]]; then
    cat "$DIR/$name.err" >&2
    fail "'levelsetd $*' exited with $rc"
  fi
  pass
}

# run_fail NAME PATTERN ARGS...: must exit with 0 < code < 128 and print exactly one stderr
# line that starts with "levelsetd: " and matches PATTERN (extended regex, case-insensitive).
run_fail() {
  local name=$1 pattern=$2
  shift 2
  local rc=0
  "$BIN" "$@" >"$DIR/$name.out" 2>"$DIR/$name.err" || rc=$?
  local err lines
  err=$(cat "$DIR/$name.err")
  lines=$(wc -l <"$DIR/$name.err")
  if [[ $rc -eq 0 ]]; then
    soft_fail "'levelsetd $*' succeeded but should have failed"
  elif [[ $rc -ge 128 ]]; then
    soft_fail "'levelsetd $*' died with signal $((rc - 128))"
  elif [[ $lines -ne 1 ]]; then
    soft_fail "'levelsetd $*' (exit $rc): expected one stderr line, got $lines: $err"
  elif ! grep -q '^levelsetd: ' "$DIR/$name.err"; then
    soft_fail "'levelsetd $*' (exit $rc): stderr does not start with 'levelsetd: ': $err"
  elif ! grep -qiE "$pattern" "$DIR/$name.err"; then
    soft_fail "'levelsetd $*' (exit $rc): stderr does not match /$pattern/: $err"
  else
    pass
  fi
}

# json_check FILE PYTHON_EXPR...: each expression, evaluated with j = the parsed JSON (and s =
# the parsed stats JSON when STATS is set), must be true.
json_check() {
  local file=$1
  shift
  STATS=${STATS:-} "$PY" - "$file" "$@" <<'EOF' || fail "JSON check on $1"
import json, math, os, sys
path, exprs = sys.argv[1], sys.argv[2:]
with open(path) as f:
    j = json.load(f)
s = None
if os.environ.get("STATS"):
    with open(os.environ["STATS"]) as f:
        s = json.load(f)
for e in exprs:
    if not eval(e, {"math": math, "os": os}, {"j": j, "s": s}):
        print(f"check failed: {e}\n{json.dumps(j, indent=1)[:2000]}", file=sys.stderr)
        sys.exit(1)
EOF
  checks=$((checks + $# - 1))
}

# cli_finish: the summary line; exit 1 when any soft check failed.
cli_finish() {
  if [[ $failures -gt 0 ]]; then
    echo "$CLI_TEST: $failures checks FAILED, $checks passed" >&2
    exit 1
  fi
  echo "$CLI_TEST: $checks checks passed"
}
