#!/usr/bin/python3
"""bench_server: the daemon under load (printed figures, not timed tests).

1. Latency of small GETs (GET /api/v1/sessions/{id}) from 64 connections (wrk, 4 threads)
   while an evolution job runs on another session: p50 / p90 / p99 against the target p99 < 10 ms.
2. Mesh download of a ~1M-triangle session as binary PLY: time to first byte, total time and
   throughput (cold: extracted on request; warm: from the server's cache).
3. Served vs batch: the same evolve job file through POST /api/v1/jobs (submit to the final
   event) and through `levelsetd run`; the overhead against the target < 5 %.

Usage: bench_server.py LEVELSETD SCRATCH_DIR [--quick]
"""
import os
import re
import shutil
import subprocess
import sys
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "integration"))
from daemon_harness import Daemon  # noqa: E402

BIN, SCRATCH = sys.argv[1], sys.argv[2]
QUICK = "--quick" in sys.argv
shutil.rmtree(SCRATCH, ignore_errors=True)
os.makedirs(SCRATCH)


def wrk_latency(url, seconds):
    out = subprocess.run(["wrk", "-t4", "-c64", f"-d{seconds}s", "--latency", url], capture_output=True, text=True,
                         timeout=seconds + 60).stdout
    pct = {}
    for p, value, unit in re.findall(r"^\s+(\d+)%\s+([\d.]+)(us|ms|s)\s*$", out, re.M):
        pct[int(p)] = float(value) * {"us": 1e-3, "ms": 1.0, "s": 1e3}[unit]
    rps = re.search(r"Requests/sec:\s+([\d.]+)", out)
    errors = re.search(r"Non-2xx or 3xx responses: (\d+)", out)
    return pct, float(rps.group(1)) if rps else 0.0, int(errors.group(1)) if errors else 0


def download(url):
    t0 = time.monotonic()
    with urllib.request.urlopen(url, timeout=600) as r:
        first = r.read(1)
        ttfb = time.monotonic() - t0
        n = len(first) + len(r.read())
    return ttfb, time.monotonic() - t0, n


d = Daemon(BIN, os.path.join(SCRATCH, "data"), "--max-jobs", "1")
try:
    # 1. small GETs while a job runs
    _, _, probe = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 32}})
    _, _, busy = d.post("/api/v1/sessions", {"primitive": "knot", "raster": {"resolution": 128 if not QUICK else 64}})
    _, _, job = d.post(f"/api/v1/sessions/{busy['id']}/jobs",
                       {"op": "evolve", "speed": "-(k1+k2)", "steps": 100000, "report_every": 0})
    pct, rps, errors = wrk_latency(f"{d.url}/api/v1/sessions/{probe['id']}", 2 if QUICK else 10)
    d.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
    d.wait_job(job["id"])
    print(f"small GETs, 64 connections, a job running: p50 {pct.get(50, float('nan')):.2f} ms, "
          f"p90 {pct.get(90, float('nan')):.2f} ms, p99 {pct.get(99, float('nan')):.2f} ms "
          f"(target p99 < 10 ms), {rps:.0f} requests/s, {errors} errors")

    # 2. mesh download of a large session
    resolution = 96 if QUICK else 340
    status, _, big = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": resolution}})
    url = f"{d.url}/api/v1/sessions/{big['id']}/mesh?format=ply"
    ttfb_cold, total_cold, size = download(url)
    ttfb_warm, total_warm, _ = download(url)
    triangles = (size - 300) // 25  # binary PLY: 24 bytes a vertex (~0.5 per triangle), 13 bytes a face
    print(f"mesh download, sphere at resolution {resolution} (~{triangles / 1e6:.2f}M triangles, {size / 1e6:.1f} MB PLY): "
          f"cold TTFB {ttfb_cold * 1e3:.0f} ms, total {total_cold:.2f} s; warm TTFB {ttfb_warm * 1e3:.1f} ms, "
          f"total {total_warm:.3f} s, {size / 1e6 / max(total_warm, 1e-9):.0f} MB/s")

    # 3. served vs batch, the same job file
    conf = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "configs", "jobs", "evolve_dumbbell.conf")
    text = open(conf).read()
    sets = ["raster.resolution=64" if QUICK else "raster.resolution=128", "evolve.report_every=0"]
    t0 = time.monotonic()
    subprocess.run([BIN, "run", conf, "-q", "-o", os.path.join(SCRATCH, "batch"), *sum([["--set", s] for s in sets], [])],
                   check=True, capture_output=True)
    batch = time.monotonic() - t0
    t0 = time.monotonic()
    _, _, job = d.post("/api/v1/jobs", {"config": text, "set": sets, "name": "evolve_dumbbell.conf"})
    final = d.wait_job(job["id"])
    served = time.monotonic() - t0
    print(f"served vs batch (evolve_dumbbell, {sets[0]}): served {served:.3f} s ({final['state']}), "
          f"batch {batch:.3f} s (process start included): overhead {100 * (served / batch - 1):+.1f} % (target < 5 %)")
finally:
    d.stop()
