#!/usr/bin/python3
"""The README's Service walk-through, run as written against a real daemon on a free port.

Usage: readme_service.py LEVELSETD README.md SCRATCH_DIR
The ```sh block after "A walk-through with curl" runs under bash -euo pipefail in SCRATCH_DIR
with LEVELSET_URL set; its output must show the job succeeded, the version 2, the formula
refused, and the downloaded meshes must be there (the kitten's watertight).
"""
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from daemon_harness import Daemon, off_topology  # noqa: E402

levelsetd, readme, scratch = sys.argv[1:4]
shutil.rmtree(scratch, ignore_errors=True)
os.makedirs(scratch)
text = open(readme, encoding="utf-8").read()
m = re.search(r"A walk-through with curl.*?```sh\n(.*?)```", text, re.S)
if not m:
    sys.exit("readme_service: no walk-through block in the README")
script = m.group(1)
d = Daemon(levelsetd, os.path.join(scratch, "data"))
try:
    r = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=scratch, capture_output=True, text=True,
                       timeout=600, env={**os.environ, "LEVELSET_URL": d.url})
finally:
    d.stop()
lines = r.stdout.splitlines()
problems = []
if r.returncode != 0:
    problems.append(f"exit {r.returncode}: {r.stderr[-1500:]}")
for expected in ('{"status":"ok"}', "event: done", "succeeded", "2", "parse_error"):
    if expected not in lines:
        problems.append(f"no output line '{expected}' in {lines}")
for f in ("torus.ply", "kitten.off"):
    if not os.path.isfile(os.path.join(scratch, f)) or os.path.getsize(os.path.join(scratch, f)) < 1000:
        problems.append(f"{f} was not downloaded")
if not problems:
    topo = off_topology(open(os.path.join(scratch, "kitten.off")).read())
    if not topo[2]:
        problems.append(f"kitten.off is not watertight: {topo}")
if problems:
    print("readme_service: FAILED:\n" + "\n".join(problems), file=sys.stderr)
    sys.exit(1)
print(f"readme_service: the walk-through ran as written ({len(lines)} output lines)")
