#!/usr/bin/python3
"""Runs one shipped job (configs/jobs/STEM.conf) through the real levelsetd at a reduced
size and asserts its outcome from the stats JSON and the files it wrote. Every job file must
have an entry here: a job without asserted outcomes fails.

Usage: check_job.py LEVELSETD JOB.conf SCRATCH_DIR
"""
import json
import math
import os
import shutil
import subprocess
import sys


def mesh_ok(m, genus=None, components=None):
    assert m["watertight"] and m["manifold"] and m["oriented"], m
    if genus is not None:
        assert m["genus"] == genus, ("genus", m["genus"], "expected", genus)
    if components is not None:
        assert m["components"] == components, ("components", m["components"], "expected", components)


def check_evolve_dumbbell(run):
    # Mean curvature flow pinches the dumbbell's bar (thesis fig. 3.1) ...
    s = run(["--set", "raster.resolution=48"])
    assert s["evolution"]["stop"] == "completed" and abs(s["evolution"]["time"] - 0.02) < 1e-9, s["evolution"]
    mesh_ok(s["mesh_before"], genus=0, components=1)
    mesh_ok(s["mesh"], genus=0, components=2)
    assert s["mesh"]["volume"] < s["mesh_before"]["volume"], "mean curvature flow shrinks"
    # ... the mean-Gaussian flow does not.
    s = run(["--set", "raster.resolution=48", "--set", "evolve.speed=mean-gaussian"])
    mesh_ok(s["mesh"], genus=0, components=1)


CHECKS = {
    "evolve_dumbbell": check_evolve_dumbbell,
}


def main():
    levelsetd, job, scratch = sys.argv[1:4]
    stem = os.path.basename(job)[: -len(".conf")]
    if stem not in CHECKS:
        sys.exit(f"check_job: no asserted outcome for {stem}: add one to {__file__}")
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(scratch)
    runs = [0]

    def run(extra):
        runs[0] += 1
        out = os.path.join(scratch, f"run{runs[0]}")
        cmd = [levelsetd, "run", job, "-o", out, "-q"] + extra
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"check_job: {' '.join(cmd)} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
        stats = json.load(open(os.path.join(out, stem + ".stats.json")))
        for path in stats["outputs"]:
            assert os.path.getsize(path) > 0, f"empty output {path}"
        assert os.path.exists(os.path.join(out, stem + ".log")), "no log"
        return stats

    CHECKS[stem](run)
    print(f"check_job: {stem}: {runs[0]} run(s), outcomes asserted")


if __name__ == "__main__":
    main()
