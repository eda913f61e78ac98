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


def radius_of(volume):
    return (3 * volume / (4 * math.pi)) ** (1 / 3)


def check_offset_knot(run):
    # +D then -D on the knot: the gap between its strands (0.8 apart) fills and stays filled.
    s = run(["--set", "raster.resolution=64"])
    for k in ("before", "outward", "after"):
        assert s[k]["watertight"] and s[k]["components"] == 1 and s[k]["genus"] == 1, (k, s[k])
    assert s["outward"]["volume"] > 5 * s["before"]["volume"], (s["outward"], s["before"])
    assert s["after"]["volume"] > 1.5 * s["before"]["volume"], "the closing did not keep the filled gap"
    assert s["after"]["volume"] < s["outward"]["volume"]
    # The offset itself is exact on a sphere: radius 1 + D (D = 0.35) within a quarter voxel.
    s = run(["--set", "raster.resolution=48", "--set", "input.shape=sphere", "--set", "offset.back=no"])
    h = 2 * (1 + 3 * 2 / 48) / 48  # about: the box of the unit sphere padded by the band
    r = radius_of(s["after"]["volume"])
    assert abs(r - 1.35) < 0.25 * h, ("radius", r, "expected", 1.35)


def check_fair_elephant(run):
    s = run(["--set", "raster.resolution=96"])
    b, a = s["before"], s["after"]
    assert a["watertight"], a
    assert a["mean_curvature"]["variance"] < 0.5 * b["mean_curvature"]["variance"], (b, a)
    assert abs(a["volume"] / b["volume"] - 1) < 0.01, ("volume-preserving flow", b["volume"], a["volume"])
    assert s["fair"]["steps"] == 40


def check_minmax_elephant(run):
    s = run(["--set", "raster.resolution=96"])
    b, a, m = s["before"], s["after"], s["minmax"]
    assert m["steady"] and 0 < m["steady_step"] <= m["steps"] < 400, m
    assert m["history"][-1][2] < 1e-3, m["history"][-1]
    assert a["watertight"] and a["genus"] == b["genus"] and a["components"] == b["components"], (b, a)
    assert a["mean_curvature"]["variance"] < b["mean_curvature"]["variance"], (b, a)
    assert abs(a["volume"] / b["volume"] - 1) < 0.01, (b["volume"], a["volume"])


def check_csg_knot_sphere(run):
    base = ["--set", "raster.resolution=64", "--set", "output.mesh=none"]
    u = run(base + ["--set", "csg.op=union"])
    i = run(base + ["--set", "csg.op=intersection"])
    d = run(base + ["--set", "csg.op=difference"])
    va, vb = u["a"]["volume"], u["b"]["volume"]
    vu, vi, vd = u["after"]["volume"], i["after"]["volume"], d["after"]["volume"]
    assert vi > 0.05 * vb, "the sphere must overlap the knot"
    # Inclusion-exclusion, and A = (A minus B) + (A and B).
    assert abs((vu + vi) / (va + vb) - 1) < 0.01, (vu, vi, va, vb)
    assert abs((vd + vi) / va - 1) < 0.01, (vd, vi, va)
    for s in (u, i, d):
        assert s["after"]["watertight"], s["after"]


CHECKS = {
    "evolve_dumbbell": check_evolve_dumbbell,
    "offset_knot": check_offset_knot,
    "fair_elephant": check_fair_elephant,
    "minmax_elephant": check_minmax_elephant,
    "csg_knot_sphere": check_csg_knot_sphere,
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
