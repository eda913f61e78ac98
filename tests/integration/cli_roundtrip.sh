#!/usr/bin/env bash
# CLI round trips through the real levelsetd binary.
# Usage: cli_roundtrip.sh LEVELSETD_BINARY SCRATCH_DIR
# Builds every builtin shape with `primitive`, reads it back with `info` (text and JSON,
# checked against the --stats JSON) and runs the error paths: each must exit non-zero (never
# by a signal) with one line "levelsetd: ..." on stderr that names the problem.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 LEVELSETD_BINARY SCRATCH_DIR" >&2
  exit 2
fi
BIN=$1
DIR=$2
PY=/usr/bin/python3
rm -rf "$DIR"
mkdir -p "$DIR"

CLI_TEST=cli_roundtrip
source "$(dirname "$0")/cli_lib.sh"

# --- version and help -----------------------------------------------------------------------
run_ok version --version
grep -qE '^levelsetd [0-9]+\.[0-9]+\.[0-9]+' "$DIR/version.out" || fail "--version: $(cat "$DIR/version.out")"
pass
run_ok help --help
if ! grep -q 'primitive' "$DIR/help.out" || ! grep -q 'info' "$DIR/help.out"; then
  fail "--help lists no subcommands"
fi
pass
run_ok primitive_help primitive --help
if ! grep -q -- '--resolution' "$DIR/primitive_help.out" || ! grep -q -- '--band' "$DIR/primitive_help.out"; then
  fail "primitive --help does not list --resolution and --band"
fi
pass

# --- knot: primitive, then info --json against the stats ------------------------------------
run_ok knot primitive knot --resolution 64 --band 3 -o "$DIR/knot.lsg" --stats "$DIR/knot_stats.json"
[[ -s "$DIR/knot.lsg" ]] || fail "primitive knot wrote no file"
pass
run_ok knot_info_json info "$DIR/knot.lsg" --json
STATS="$DIR/knot_stats.json" json_check "$DIR/knot_info_json.out" \
  'j["kind"] == "narrow_band"' \
  'j["format"] == "lsg"' \
  'j["active_voxels"] > 0' \
  'j["active_voxels"] == s["active_voxels"]' \
  'j["bricks"] > 0' \
  'j["bricks"] == s["bricks"]' \
  'j["bytes_per_active_voxel"] <= 6' \
  'j["voxel_size"] == s["voxel_size"]' \
  'j["file_bytes"] == s["file_bytes"] == os.path.getsize(j["file"])' \
  'j["band_half_width_voxels"] == 3' \
  'j["far_inside"] is False' \
  's["op"] == "primitive" and s["shape"] == "knot" and s["resolution"] == 64'
run_ok knot_info info "$DIR/knot.lsg"
grep -q 'active voxels' "$DIR/knot_info.out" || fail "info text does not mention 'active voxels'"
pass
active=$("$PY" -c 'import json,sys; print(json.load(open(sys.argv[1]))["active_voxels"])' \
  "$DIR/knot_stats.json")
grep -qE "active voxels: +$active\$" "$DIR/knot_info.out" || fail "info text does not show $active active voxels"
pass

# --- every other shape ----------------------------------------------------------------------
for shape in sphere box torus dumbbell; do
  run_ok "$shape" primitive "$shape" --resolution 32 --band 2 -o "$DIR/$shape.lsg" --stats "$DIR/${shape}_stats.json"
  run_ok "${shape}_info" info "$DIR/$shape.lsg" --json
  STATS="$DIR/${shape}_stats.json" json_check "$DIR/${shape}_info.out" \
    'j["kind"] == "narrow_band"' \
    'j["active_voxels"] > 0 and j["active_voxels"] == s["active_voxels"]' \
    'j["bricks"] > 0 and j["bricks"] == s["bricks"]' \
    'j["voxel_size"] == s["voxel_size"]' \
    'j["band_half_width_voxels"] == 2' \
    'j["world_bounds"] is not None'
done

# --- error paths ----------------------------------------------------------------------------
run_fail missing 'io_error.*missing\.lsg.*(does not exist|no such)' info "$DIR/missing.lsg"
head -c 100 "$DIR/knot.lsg" >"$DIR/cut.lsg"
run_fail truncated '^levelsetd: truncated.*cut\.lsg.*byte 100' info "$DIR/cut.lsg"
cp "$DIR/knot.lsg" "$DIR/damaged.lsg"
printf '\xff' | dd of="$DIR/damaged.lsg" bs=1 seek=1000 conv=notrunc status=none
run_fail damaged '^levelsetd: corrupt.*damaged\.lsg' info "$DIR/damaged.lsg"
echo 'hello' >"$DIR/notes.qqq"
run_fail extension 'unsupported_format.*notes\.qqq.*unknown extension' info "$DIR/notes.qqq"
run_fail bad_shape 'nosuchshape' primitive nosuchshape -o "$DIR/bad_shape.lsg"
expect_absent "$DIR/bad_shape.lsg" "primitive nosuchshape left a file"
run_fail low_resolution 'resolution' primitive sphere --resolution 4 -o "$DIR/low.lsg"
expect_absent "$DIR/low.lsg" "primitive --resolution 4 left a file"
run_fail no_dir 'no/such/dir|nodir' primitive sphere --resolution 16 -o "$DIR/no/such/dir/x.lsg"
expect_absent "$DIR/no" "primitive into a missing directory created it"
# Nothing but the expected files: no temporary leftovers from the atomic writes.
leftovers=$(find "$DIR" -name '*.tmp-*' | wc -l)
if [[ $leftovers -eq 0 ]]; then pass; else soft_fail "$leftovers temporary files left in $DIR"; fi

# Outputs never clobber (issue 14): no device or symlink replaced, no input overwritten, no
# two outputs to one file; each refused before any work, leaving the file as it was.
run_ok clobber_knot primitive knot --resolution 24 --band 3 -o "$DIR/clobber.lsg"
before=$(sha256sum "$DIR/clobber.lsg")
mkfifo "$DIR/clobber.fifo"
ln -sf "$DIR/elsewhere.lsg" "$DIR/clobber_link.lsg"
run_fail clobber_fifo "not a regular file" primitive knot --resolution 24 --band 3 -o "$DIR/clobber.fifo"
[[ -p "$DIR/clobber.fifo" ]] && pass || soft_fail "the FIFO was replaced"
run_fail clobber_link "symbolic link" primitive knot --resolution 24 --band 3 -o "$DIR/clobber_link.lsg"
[[ -L "$DIR/clobber_link.lsg" && ! -e "$DIR/elsewhere.lsg" ]] && pass || soft_fail "the symlink was replaced or followed"
run_fail clobber_input "also an input" redistance "$DIR/clobber.lsg" --method sweep -o "$DIR/clobber.lsg"
run_fail clobber_stats "also an input" mesh "$DIR/clobber.lsg" -o "$DIR/clobber.ply" --stats "$DIR/clobber.lsg"
run_fail clobber_twice "two outputs" mesh "$DIR/clobber.lsg" -o "$DIR/clobber.ply" --stats "$DIR/./clobber.ply"
[[ "$(sha256sum "$DIR/clobber.lsg")" == "$before" ]] && pass || soft_fail "the input changed"
expect_absent "$DIR/clobber.ply" "an output was written although the command was refused"
ls "$DIR"/*.tmp-* >/dev/null 2>&1 && soft_fail "temp files left behind" || pass

cli_finish
