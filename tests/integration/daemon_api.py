#!/usr/bin/python3
"""The daemon over real HTTP (issue 15): a real `levelsetd serve` on a free loopback port.

Usage: daemon_api.py LEVELSETD SCRATCH_DIR CGAL_DATA TEST
TEST is one of the functions below named test_<TEST>; each is its own ctest.
"""
import concurrent.futures
import json
import os
import random
import resource
import shutil
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from daemon_harness import Daemon, off_topology, upload, write_sphere_cloud  # noqa: E402

BIN, SCRATCH, CGAL = sys.argv[1], sys.argv[2], sys.argv[3]
TOKEN_RW, TOKEN_RO = "rw-token-0123456789abcdef", "ro-token-0123456789abcdef"


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def fresh(name):
    d = os.path.join(SCRATCH, name)
    shutil.rmtree(d, ignore_errors=True)
    if os.path.exists(d + ".log"):
        os.remove(d + ".log")
    os.makedirs(os.path.dirname(d), exist_ok=True)
    return d


def healthy(d):
    status, _, body = d.get("/healthz")
    check(status == 200 and body["status"] == "ok", f"/healthz after a refusal: {status} {body}")


def sphere_session(d, resolution=48, name="s"):
    status, _, s = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": resolution}, "name": name})
    check(status == 201, f"create session: {status} {s}")
    return s


def long_evolve(d, session_id, steps=100000, speed="1"):
    status, hdrs, job = d.post(f"/api/v1/sessions/{session_id}/jobs",
                               {"op": "evolve", "speed": speed, "steps": steps, "report_every": 0})
    check(status == 202 and hdrs.get("Location") == f"/api/v1/jobs/{job['id']}", f"submit: {status} {job}")
    return job


def wait_running(d, job_id, min_step=1, timeout=60):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        job = d.get(f"/api/v1/jobs/{job_id}")[2]
        if job["state"] == "running" and job["progress"].get("step", 0) >= min_step:
            return job
        if job["state"] not in ("queued", "running"):
            raise AssertionError(f"job ended early: {job}")
        d.events(f"/api/v1/jobs/{job_id}/events", until=lambda e: e[1] == "progress" and e[2].get("step", 0) >= min_step,
                 timeout=timeout)
    raise AssertionError("job never ran")


# ---- the API surface ---------------------------------------------------------------------------

def test_surface():
    d = Daemon(BIN, fresh("surface"))
    try:
        status, _, info = d.get("/api/v1")
        check(status == 200 and info["api"] == "v1" and info["limits"]["max_jobs"] >= 1, f"/api/v1: {info}")
        check({o["op"] for o in info["operations"]} >= {"evolve", "redistance", "offset", "fair", "minmax", "csg",
                                                       "reconstruct", "segment", "cpt", "mesh", "measure"},
              "operations listed")
        check(d.get("/readyz")[0] == 200, "readyz")
        status, hdrs, metrics = d.request("GET", "/metrics")
        check(status == 200 and b"# TYPE levelset_requests_total counter" in metrics, "metrics")
        # Large buffers come from the huge block pool (levelsetd links its operator new): a
        # session whose band takes several MB maps some.
        status, _, made = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 192}})
        check(status in (200, 201), f"a 192^3 sphere: {made}")
        metrics = d.request("GET", "/metrics")[2].decode()
        values = {line.split()[0]: float(line.split()[1]) for line in metrics.splitlines()
                  if line.startswith("levelset_huge_blocks_")}
        check(set(values) == {"levelset_huge_blocks_live_bytes", "levelset_huge_blocks_cached_bytes",
                              "levelset_huge_blocks_mapped_total", "levelset_huge_blocks_reused_total"},
              f"huge block metrics: {values}")
        check(values["levelset_huge_blocks_mapped_total"] > 0 and values["levelset_huge_blocks_live_bytes"] > 0,
              f"the daemon's large buffers come from the pool: {values}")
        d.request("DELETE", f"/api/v1/sessions/{made['id']}")
        status, hdrs, _ = d.request("GET", "/healthz")
        check(len(hdrs.get("X-Request-Id", "")) > 0, "X-Request-Id")
        status, hdrs, _ = d.request("GET", "/healthz", headers={"X-Request-Id": "my-request-1"})
        check(hdrs.get("X-Request-Id") == "my-request-1", "the client's request id is kept")
        # Every documented route is registered (none answers "no_route"), and nothing else is.
        status, _, doc = d.get("/api/v1/openapi.json")
        check(status == 200 and doc["openapi"].startswith("3.0"), "openapi document")
        documented = 0
        for path, methods in doc["paths"].items():
            concrete = path
            for name in ("{id}", "{jid}", "{sid}", "{name}"):
                concrete = concrete.replace(name, "x-s-0000000000000000")
            for method in methods:
                if path.endswith("/events"):
                    continue  # a stream of an unknown id: 404 not_found below is enough
                st, _, body = d.json_request(method.upper(), concrete, {} if method in ("post", "patch") else None)
                code = body.get("error", {}).get("code") if isinstance(body, dict) else None
                check(code != "no_route", f"{method.upper()} {path} is documented but not registered")
                documented += 1
        check(documented >= 25, f"only {documented} routes documented")
        st, _, body = d.get("/api/v1/nothing-here")
        check(st == 404 and body["error"]["code"] == "no_route", "an unknown route is a JSON 404 no_route")
        st, _, body = d.get("/api/v1/sessions/x-s-0000000000000000/events")
        check(st == 404 and body["error"]["code"] == "not_found", "events of an unknown session")
    finally:
        d.stop()


# ---- end to end ---------------------------------------------------------------------------------

def batch_genus(points, resolution, workdir):
    """The batch run's genus, for comparison with the served one."""
    mesh = os.path.join(workdir, "batch.off")
    subprocess.run([BIN, "reconstruct", points, "--resolution", str(resolution), "-o", mesh], check=True,
                   capture_output=True)
    with open(mesh) as f:
        return off_topology(f.read())


def test_reconstruct_kitten():
    work = fresh("kitten")
    d = Daemon(BIN, work)
    try:
        points = os.path.join(CGAL, "points_3", "kitten.xyz")
        status, hdrs, up = upload(d, points, "xyz")
        check(status == 201 and up["kind"] == "points" and up["summary"]["points"] > 5000, f"upload: {status} {up}")
        status, _, job = d.post("/api/v1/sessions", {"upload": up["id"], "name": "kitten", "raster": {"resolution": 64}})
        check(status == 202, f"create from points: {status} {job}")
        events = d.events(f"/api/v1/jobs/{job['id']}/events", until=lambda e: e[1] == "done", timeout=300)
        types = [e[1] for e in events]
        check(types[0] == "state" and types[-1] == "done" and "log" in types, f"event stream: {types[:10]}...")
        check(all(events[i][0] < events[i + 1][0] for i in range(1, len(events) - 1)), "event ids increase")
        final = d.get(f"/api/v1/jobs/{job['id']}")[2]
        check(final["state"] == "succeeded", f"job: {final}")
        sid = final["result"]["session"]
        # The reconstruction input stays with the session and shows in its frames (table 4.1 I).
        info = d.get(f"/api/v1/sessions/{sid}")[2]
        check(info["points"] and info["points"]["upload"] == up["id"] and info["points"]["points"] == up["summary"]["points"],
              f"the session keeps its input points: {info.get('points')}")
        cloud_only = f"/api/v1/sessions/{sid}/frame?width=640&height=480&format=png&shading=none"
        shown = foreground(decode(d.request("GET", cloud_only)[2]))
        check(shown > 500, f"the point cloud draws: {shown} px")
        check(foreground(decode(d.request("GET", cloud_only + "&cloud=off")[2])) == 0, "cloud=off hides it")
        check(d.request("DELETE", f"/api/v1/uploads/{up['id']}")[0] == 204, "the upload can go")
        bigger = foreground(decode(d.request("GET", cloud_only + "&cloud_size=4")[2]))
        check(bigger > 1.5 * shown, f"the session's copy outlives the upload; bigger points cover more: {bigger} vs {shown}")
        status, _, body = d.json_request("PATCH", f"/api/v1/sessions/{sid}", {"points": None})
        check(status == 200 and body["points"] is None, f"PATCH points null: {status} {body}")
        check(foreground(decode(d.request("GET", cloud_only)[2])) == 0, "a detached cloud no longer draws")
        status, _, mesh_up = upload(d, os.path.join(CGAL, "meshes", "knot1.off"), "off")
        status, _, body = d.json_request("PATCH", f"/api/v1/sessions/{sid}", {"points": mesh_up["id"]})
        check(status == 422 and body["error"]["details"]["field"] == "body.points", f"a mesh is not a point cloud: {status} {body}")
        status, hdrs, mesh = d.request("GET", f"/api/v1/sessions/{sid}/mesh?format=off")
        check(status == 200 and hdrs.get("ETag"), "mesh download with an ETag")
        served = off_topology(mesh.decode())
        batch = batch_genus(points, 64, os.path.dirname(work))
        check(served[2], f"the served mesh is not watertight: {served}")
        check(served[3] == batch[3] and served[4] == batch[4], f"genus/components served {served} vs batch {batch}")
        status, _, _ = d.request("GET", f"/api/v1/sessions/{sid}/mesh?format=off", headers={"If-None-Match": hdrs["ETag"]})
        check(status == 304, f"If-None-Match gives 304, got {status}")
        status, _, band = d.request("GET", f"/api/v1/sessions/{sid}/band")
        check(status == 200 and len(band) > 1000, "band download")
        status, hdrs, recs = d.request("GET", f"/api/v1/sessions/{sid}/voxels?min=-0.001&max=0.001&fields=value,closest,curvature&limit=100")
        check(status == 200 and hdrs.get("X-Fields") == "x,y,z,value,cx,cy,cz,curvature", f"voxels: {hdrs}")
        check(len(recs) == 32 * min(100, int(hdrs["X-Total-Count"])), f"voxel records: {len(recs)} bytes")
    finally:
        d.stop()


def test_sessions_from_uploads():
    """A session from each kind of upload: a band at once, a mesh by CPT, an image by segmentation."""
    work = fresh("uploads")
    d = Daemon(BIN, work)
    try:
        band = os.path.join(SCRATCH, "uploads-torus.lsg")
        subprocess.run([BIN, "primitive", "torus", "-r", "32", "-o", band], check=True, capture_output=True)
        status, _, up = upload(d, band, "lsg")
        check(status == 201 and up["kind"] == "band", f"band upload: {status} {up}")
        status, hdrs, s = d.post("/api/v1/sessions", {"upload": up["id"], "name": "torus"})
        check(status == 201 and s["name"] == "torus" and hdrs["Location"].endswith(s["id"]), f"from a band: {s}")
        status, _, up = upload(d, os.path.join(CGAL, "meshes", "knot1.off"), "off")
        check(status == 201 and up["kind"] == "mesh" and up["summary"]["triangles"] > 1000, f"mesh upload: {up}")
        status, _, job = d.post("/api/v1/sessions", {"upload": up["id"], "raster": {"resolution": 48}})
        final = d.wait_job(job["id"])
        check(final["state"] == "succeeded" and final["op"] == "cpt", f"from a mesh: {final}")
        mesh = off_topology(d.request("GET", f"/api/v1/sessions/{final['result']['session']}/mesh?format=off")[2].decode())
        check(mesh[2] and mesh[3] == 1, f"the knot's CPT surface: watertight, genus 1: {mesh}")
        status, _, up = upload(d, os.path.join(CGAL, "images", "liver.inr.gz"), "inr")
        check(status == 201 and up["kind"] == "image", f"image upload: {up}")
        status, _, job = d.post("/api/v1/sessions", {"upload": up["id"], "input": {"downsample": 4}, "seed_above": 127.5})
        final = d.wait_job(job["id"])
        check(final["state"] == "succeeded" and final["op"] == "segment", f"from an image: {final.get('error')}")
        status, _, body = d.get(f"/api/v1/uploads/{up['id']}")
        check(status == 200 and body["id"] == up["id"], "GET an upload")
        check(d.json_request("DELETE", f"/api/v1/uploads/{up['id']}")[0] == 204, "DELETE an upload")
        check(d.get(f"/api/v1/uploads/{up['id']}")[0] == 404, "a deleted upload is gone")
        status, _, body = d.json_request("POST", "/api/v1/uploads?format=exe", b"MZ",
                                         headers={"Content-Type": "application/octet-stream"})
        check(status == 415, f"unknown upload format: {status}")
    finally:
        d.stop()


def test_knot_job_file():
    """A job file over the API: the shipped knot reconstruction, its final band a session."""
    d = Daemon(BIN, fresh("knotjob"))
    try:
        with open(os.path.join(os.path.dirname(__file__), "..", "..", "configs", "jobs", "reconstruct_knot.conf")) as f:
            text = f.read()
        status, _, job = d.post("/api/v1/jobs", {"config": text, "name": "reconstruct_knot.conf",
                                                 "set": ["raster.resolution=64", "input.count=8000"]})
        check(status == 202, f"job file: {status} {job}")
        final = d.wait_job(job["id"])
        check(final["state"] == "succeeded", f"job: {final}")
        check("reconstruct_knot.ply" in final["result"]["files"], f"files: {final['result']['files']}")
        sid = final["result"]["session"]
        served = off_topology(d.request("GET", f"/api/v1/sessions/{sid}/mesh?format=off")[2].decode())
        check(served[2] and served[3] == 1 and served[4] == 1, f"the knot: watertight genus 1: {served}")
        status, _, ply = d.request("GET", f"/api/v1/jobs/{job['id']}/files/reconstruct_knot.ply")
        check(status == 200 and ply.startswith(b"ply"), "the job's mesh file")
        status, _, body = d.post("/api/v1/jobs", {"config": "job = offset\ninput { shape = knot\n", "name": "bad.conf"})
        check(status == 400 and "bad.conf:" in body["error"]["message"], f"a malformed job file: {status} {body}")
        status, _, body = d.post("/api/v1/jobs", {"config": "job = offset\ninput { mesh = ../../etc/passwd }\n"
                                                            "offset { distance = 0.1 }\n"})
        final = d.wait_job(body["id"])
        check(final["state"] == "failed" and "leaves" in final["error"]["message"], f"a path outside: {final}")
    finally:
        d.stop()


# ---- cancel, stop, restart ------------------------------------------------------------------

def test_cancel_and_stop():
    d = Daemon(BIN, fresh("cancelstop"))
    try:
        s = sphere_session(d)
        before = d.request("GET", f"/api/v1/sessions/{s['id']}/band")[2]
        job = long_evolve(d, s["id"])
        wait_running(d, job["id"], 5)
        status, _, _ = d.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
        check(status == 200, "cancel")
        final = d.wait_job(job["id"])
        check(final["state"] == "cancelled", f"cancelled: {final['state']}")
        now = d.get(f"/api/v1/sessions/{s['id']}")[2]
        check(now["version"] == 1 and d.request("GET", f"/api/v1/sessions/{s['id']}/band")[2] == before,
              "cancel keeps the old state")
        job = long_evolve(d, s["id"])
        reached = wait_running(d, job["id"], 20)["progress"]["step"]
        status, _, _ = d.post(f"/api/v1/jobs/{job['id']}/stop")
        check(status == 200, "stop")
        final = d.wait_job(job["id"])
        check(final["state"] == "succeeded" and final["result"]["stopped"], f"stopped: {final}")
        steps = final["result"]["evolution"]["steps"]
        check(reached <= steps < 100000, f"stop kept the state reached ({steps} steps, >= {reached})")
        now = d.get(f"/api/v1/sessions/{s['id']}")[2]
        check(now["version"] == 2 and now["band"]["bounds"]["max"][0] > s["band"]["bounds"]["max"][0],
              "stop keeps the new state (the sphere grew)")
        # Stop of a job without steps is refused.
        j = d.post(f"/api/v1/sessions/{s['id']}/jobs", {"op": "measure"})[2]
        d.wait_job(j["id"])
        status, _, body = d.post(f"/api/v1/jobs/{j['id']}/stop")
        check(status == 409, f"stop of a measure: {status} {body}")
    finally:
        d.stop()


def test_restart_and_resume():
    data = fresh("restart")
    d = Daemon(BIN, data, "--checkpoint-seconds", "0.3")
    s = sphere_session(d, 64)
    d.post(f"/api/v1/sessions/{s['id']}/snapshots", {"name": "start"})
    # Mean curvature flow: bounded work per step (the sphere shrinks; it vanishes after ~2300).
    job = long_evolve(d, s["id"], steps=1000, speed="-(k1+k2)")
    wait_running(d, job["id"], 30)
    # A checkpoint lands within checkpoint_seconds; then kill -9 mid-job.
    ckpt = os.path.join(data, "sessions", s["id"], f"checkpoint-{job['id']}.json")
    t0 = time.monotonic()
    while not os.path.exists(ckpt) and time.monotonic() - t0 < 30:
        d.events(f"/api/v1/jobs/{job['id']}/events", until=lambda e: e[1] == "progress", timeout=10)
    check(os.path.exists(ckpt), "no checkpoint written")
    d.kill()
    d = Daemon(BIN, data)
    try:
        sessions = d.get("/api/v1/sessions")[2]["sessions"]
        check([x["id"] for x in sessions] == [s["id"]] and sessions[0]["version"] == 1, f"sessions back: {sessions}")
        check(sessions[0]["snapshots"] == 1, "snapshots back")
        j = d.get(f"/api/v1/jobs/{job['id']}")[2]
        check(j["state"] == "interrupted", f"a job cut off by kill -9 is interrupted: {j['state']}")
        status, _, _ = d.post(f"/api/v1/jobs/{job['id']}/resume")
        check(status == 202, "resume")
        # Last-Event-ID: 0 replays the resumed job's events from its first.
        events = d.events(f"/api/v1/jobs/{job['id']}/events", until=lambda e: e[1] == "done", timeout=300,
                          headers={"Last-Event-ID": "0"})
        resumed = [e for e in events if e[1] == "log" and "resumed from the checkpoint" in e[2]["line"]]
        check(resumed, "resumed from the checkpoint")
        final = d.get(f"/api/v1/jobs/{job['id']}")[2]
        check(final["state"] == "succeeded", f"resume completes: {final['state']} {final.get('error')}")
        check(final["progress"]["step"] == 1000, f"the resumed job ends at the requested step: {final['progress']}")
        check(d.get(f"/api/v1/sessions/{s['id']}")[2]["version"] == 2, "the resumed job committed")
    finally:
        d.stop()


def test_sigterm_during_job():
    data = fresh("sigterm")
    d = Daemon(BIN, data, "--shutdown-deadline", "10")
    s = sphere_session(d, 64)
    job = long_evolve(d, s["id"], steps=100000, speed="-(k1+k2)")
    wait_running(d, job["id"], 10)
    rc, seconds = d.stop()
    check(rc == 0 and seconds < 10, f"SIGTERM: exit {rc} after {seconds:.2f} s")
    d = Daemon(BIN, data)
    try:
        j = d.get(f"/api/v1/jobs/{job['id']}")[2]
        check(j["state"] == "interrupted", f"job after SIGTERM: {j['state']}")
        check(os.path.exists(os.path.join(data, "sessions", s["id"], f"checkpoint-{job['id']}.lsg")),
              "SIGTERM checkpointed the job")
    finally:
        d.stop()


def test_kill9_storm():
    """20 kill -9 at random moments during uploads and jobs; every session still loads."""
    data = fresh("storm")
    rng = random.Random(14)
    points = os.path.join(CGAL, "points_3", "kitten.xyz")
    mesh = os.path.join(CGAL, "meshes", "knot1.off")
    for round_ in range(20):
        d = Daemon(BIN, data, "--checkpoint-seconds", "0.05")
        log = d.read_log()
        check("not loaded" not in log, f"round {round_}: a session did not load: {log[-1500:]}")
        sessions = d.get("/api/v1/sessions")[2]["sessions"]
        for s in sessions:
            status, _, band = d.request("GET", f"/api/v1/sessions/{s['id']}/band")
            check(status == 200 and len(band) > 100, f"round {round_}: session {s['id']} band: {status}")
        def activity():
            try:
                s = sphere_session(d, 32)
                upload(d, points if round_ % 2 else mesh, "xyz" if round_ % 2 else "off")
                d.post(f"/api/v1/sessions/{s['id']}/jobs", {"op": "evolve", "speed": "-(k1+k2)", "steps": 400})
                d.post(f"/api/v1/sessions/{s['id']}/snapshots", {})
            except Exception:
                pass  # the kill may land mid-request
        t = threading.Thread(target=activity)
        t.start()
        time.sleep(rng.uniform(0.0, 0.4))
        d.kill()
        t.join()
    d = Daemon(BIN, data)
    try:
        check("not loaded" not in d.read_log(), "after the storm every session loads")
        leftovers = [f for root, _, files in os.walk(data) for f in files if ".tmp-" in f]
        check(not leftovers, f"temp files under final names' directories: {leftovers[:5]}")
    finally:
        d.stop()


def test_write_failure():
    """A write that fails (file size limit) fails the job with 507 and keeps the last version."""
    data = fresh("efbig")
    limit = 64 * 1024

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    d = Daemon(BIN, data, preexec_fn=small_files)
    try:
        s = sphere_session(d, 48)  # ~50 KB band
        status, _, job = d.post(f"/api/v1/sessions/{s['id']}/jobs", {"op": "offset", "distance": 0.6})
        final = d.wait_job(job["id"])
        check(final["state"] == "failed" and final["error"]["status"] == 507, f"job on a full disk: {final}")
        now = d.get(f"/api/v1/sessions/{s['id']}")[2]
        check(now["version"] == 1, "the last version stays")
        healthy(d)
    finally:
        d.stop()
    d = Daemon(BIN, data)
    try:
        sessions = d.get("/api/v1/sessions")[2]["sessions"]
        check(len(sessions) == 1 and sessions[0]["version"] == 1, "the session loads after the failed write")
    finally:
        d.stop()


# ---- refusals -------------------------------------------------------------------------------

def test_refusals():
    d = Daemon(BIN, fresh("refusals"), "--tokens", f"{TOKEN_RW},{TOKEN_RO}:ro", "--max-body-bytes", "2K",
               "--max-session-voxels", "20000", "--max-jobs", "1", "--max-queued-jobs", "1")
    rw = {"Authorization": "Bearer " + TOKEN_RW}
    ro = {"Authorization": "Bearer " + TOKEN_RO}
    try:
        status, hdrs, body = d.get("/api/v1/sessions")
        check(status == 401 and "Bearer" in hdrs.get("WWW-Authenticate", ""), f"no token: {status}")
        healthy(d)
        status, _, _ = d.get("/api/v1/sessions", headers={"Authorization": "Bearer wrong-token-0123456789"})
        check(status == 401, "a wrong token")
        check(d.get("/api/v1/sessions", headers=ro)[0] == 200, "read-only token on a GET")
        status, _, body = d.post("/api/v1/sessions", {"primitive": "sphere"}, headers=ro)
        check(status == 403 and body["error"]["code"] == "forbidden", f"read-only token on a POST: {status}")
        healthy(d)
        status, _, body = d.post("/api/v1/sessions", {"primitive": "sphere", "pad": "x" * 4000}, headers=rw)
        check(status == 413, f"oversized body: {status} {body}")
        healthy(d)
        status, _, body = d.json_request("POST", "/api/v1/sessions", '{"primitive":\n "sphere",,}', headers=rw)
        check(status == 400 and body["error"]["details"]["line"] == 2, f"malformed JSON: {status} {body}")
        healthy(d)
        status, _, body = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 16}}, headers=rw)
        check(status == 201, f"small session: {status} {body}")
        sid = body["id"]
        status, _, body = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": "1 + * k1", "steps": 2},
                                 headers=rw)
        check(status == 400 and "column" in body["error"]["message"], f"formula error: {status} {body}")
        healthy(d)
        bad = os.path.join(SCRATCH, "bad.off")
        with open(bad, "w") as f:
            f.write("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
        status, _, body = upload(d, bad, "off", headers=rw)
        check(status == 400 and ":6" in body["error"]["message"], f"malformed mesh: {status} {body}")
        healthy(d)
        status, _, body = d.get("/api/v1/sessions/x-s-0123456789abcdef", headers=ro)
        check(status == 404, f"unknown session: {status}")
        status, _, body = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": "1", "steps": -3},
                                 headers=rw)
        final = d.wait_job(body["id"], headers=ro) if status == 202 else None
        check(status == 422 or (final and final["state"] == "failed" and final["error"]["status"] == 422),
              f"a parameter out of range: {status} {body} {final}")
        status, _, body = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 64}}, headers=rw)
        check(status == 507 and "max_session_voxels" in body["error"]["message"], f"voxel budget: {status} {body}")
        healthy(d)
        # Busy session and full queue.
        a = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 16}}, headers=rw)[2]["id"]
        b = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 16}}, headers=rw)[2]["id"]
        c = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 16}}, headers=rw)[2]["id"]
        long_job = d.post(f"/api/v1/sessions/{a}/jobs", {"op": "evolve", "speed": "0.01", "steps": 10 ** 7,
                                                        "report_every": 0}, headers=rw)[2]
        # Running (out of the queue) before the queue is filled: one waiting job fills it.
        d.events(f"/api/v1/jobs/{long_job['id']}/events", headers=ro,
                 until=lambda e: e[1] == "progress" and e[2].get("step", 0) >= 1)
        status, _, body = d.post(f"/api/v1/sessions/{a}/jobs", {"op": "measure"}, headers=rw)
        check(status == 409, f"busy session: {status} {body}")
        status, _, queued = d.post(f"/api/v1/sessions/{b}/jobs", {"op": "measure"}, headers=rw)
        check(status == 202, f"queued: {status}")
        status, _, body = d.post(f"/api/v1/sessions/{c}/jobs", {"op": "measure"}, headers=rw)
        check(status == 429, f"full queue: {status} {body}")
        healthy(d)
        # Idempotency: a retried POST returns the first answer.
        key = {"Idempotency-Key": "retry-1", **rw}
        first = d.post(f"/api/v1/sessions/{c}/snapshots", {"name": "once"}, headers=key)
        again = d.post(f"/api/v1/sessions/{c}/snapshots", {"name": "once"}, headers=key)
        check(first[0] == 201 and again[2] == first[2] and again[1].get("Idempotent-Replayed") == "true",
              "idempotent replay")
        check(len(d.get(f"/api/v1/sessions/{c}/snapshots", headers=ro)[2]["snapshots"]) == 1, "one snapshot")
        d.json_request("DELETE", f"/api/v1/jobs/{long_job['id']}", headers=rw)
        check(d.wait_job(queued["id"], headers=ro)["state"] == "succeeded", "the queued job ran after the cancel")
        healthy(d)
    finally:
        d.stop()


def test_security_defaults():
    out = subprocess.run([BIN, "serve", "--host", "0.0.0.0", "--port", "0", "--data", fresh("insecure")],
                         capture_output=True, text=True, timeout=20)
    check(out.returncode != 0 and "token" in out.stderr, f"beyond loopback without tokens: {out.returncode} {out.stderr}")
    check(subprocess.run([BIN, "serve", "--help"], capture_output=True, text=True).stdout.count("LEVELSET_") >= 20,
          "serve --help lists the settings and their variables")
    conf = os.path.join(os.path.dirname(__file__), "..", "..", "configs", "server.conf")
    text = open(conf).read()
    help_text = subprocess.run([BIN, "serve", "--help"], capture_output=True, text=True).stdout
    import re
    for env in re.findall(r"\[LEVELSET_([A-Z_]+)\]", help_text):
        key = env.lower()
        check(re.search(rf"^(// )?{key} =", text, re.M), f"configs/server.conf does not document '{key}'")
    d = Daemon(BIN, fresh("conf"), "--config", conf, env={"LEVELSET_MAX_SESSIONS": "7"})
    try:
        check(d.get("/api/v1")[2]["limits"]["max_sessions"] == 7, "the environment overrides the file")
    finally:
        d.stop()
    d = Daemon(BIN, fresh("conf2"), "--config", conf, "--max-sessions", "9", env={"LEVELSET_MAX_SESSIONS": "7"})
    try:
        check(d.get("/api/v1")[2]["limits"]["max_sessions"] == 9, "flags override the environment")
    finally:
        d.stop()


def test_tls_cors_logs():
    """HTTPS with --tls-cert/--tls-key, CORS for the configured origin only, JSON log lines."""
    work = fresh("tls")
    os.makedirs(work)
    cert, key = os.path.join(work, "cert.pem"), os.path.join(work, "key.pem")
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", key, "-out", cert,
                    "-days", "1", "-subj", "/CN=127.0.0.1"], check=True, capture_output=True)
    d = Daemon(BIN, os.path.join(work, "data"), "--tls-cert", cert, "--tls-key", key, "--cors-origin",
               "https://viewer.example", "--log-format", "json")
    try:
        check(d.url.startswith("https://"), f"the ready line names https: {d.url}")
        status, hdrs, body = d.get("/api/v1", headers={"Origin": "https://viewer.example"})
        check(status == 200 and hdrs.get("Access-Control-Allow-Origin") == "https://viewer.example", f"CORS: {hdrs}")
        status, hdrs, body = d.get("/api/v1", headers={"Origin": "https://elsewhere.example"})
        check("Access-Control-Allow-Origin" not in hdrs, "CORS for another origin")
        status, hdrs, _ = d.request("OPTIONS", "/api/v1/sessions", headers={"Origin": "https://viewer.example"})
        check(status == 204 and "POST" in hdrs.get("Access-Control-Allow-Methods", ""), f"preflight: {status} {hdrs}")
        status, hdrs, _ = d.request("GET", "/healthz", headers={"X-Request-Id": "tls-check-1"})
    finally:
        d.stop()
    lines = [json.loads(line) for line in d.read_log().splitlines() if line.startswith("{")]
    check(any(entry.get("request_id") == "tls-check-1" and entry.get("status") == 200 for entry in lines),
          "the JSON log line carries the request id")
    plain = subprocess.run(["curl", "-s", "-o", "/dev/null", "-w", "%{http_code}", d.url.replace("https", "http") + "/healthz"],
                           capture_output=True, text=True)
    check(plain.stdout != "200", "plain HTTP to the TLS port is not served")


def test_preview_while_running():
    """While an evolution runs, mesh reads see its latest step; the committed version stays."""
    d = Daemon(BIN, fresh("preview"))
    try:
        s = sphere_session(d, 48)
        job = long_evolve(d, s["id"], steps=100000, speed="-(k1+k2)*0.01")
        wait_running(d, job["id"], 5)
        _, h1, m1 = d.request("GET", f"/api/v1/sessions/{s['id']}/mesh?format=off")
        wait_running(d, job["id"], d.get(f"/api/v1/jobs/{job['id']}")[2]["progress"]["step"] + 30)
        _, h2, m2 = d.request("GET", f"/api/v1/sessions/{s['id']}/mesh?format=off")
        check(h1["ETag"] != h2["ETag"] and m1 != m2, "the preview moves with the job")
        check(d.get(f"/api/v1/sessions/{s['id']}")[2]["version"] == 1, "the committed version stays while it runs")
        d.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
        d.wait_job(job["id"])
        _, h3, m3 = d.request("GET", f"/api/v1/sessions/{s['id']}/mesh?format=off")
        check(h3["ETag"] not in (h1["ETag"], h2["ETag"]), "after the cancel the mesh is the committed one again")
        # An application that evolves inside (fairing) previews too.
        status, _, job = d.post(f"/api/v1/sessions/{s['id']}/jobs", {"op": "fair", "flow": "mean-curvature",
                                                                    "steps": 100000})
        check(status == 202, f"fair: {status} {job}")
        seen = set()
        for _ in range(100):
            _, h, _ = d.request("GET", f"/api/v1/sessions/{s['id']}/mesh?format=off")
            seen.add(h["ETag"])
            if len(seen) >= 3:
                break
            d.events(f"/api/v1/jobs/{job['id']}/events", until=lambda e: e[1] == "progress", timeout=30)
        check(len(seen) >= 3, f"the fairing's preview moves: {len(seen)} distinct meshes")
        d.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
        check(d.wait_job(job["id"])["state"] == "cancelled", "fairing cancelled")
    finally:
        d.stop()


def test_two_replicas():
    """Session-affine routing: two daemons named as a StatefulSet would name them, each with the
    other as a peer; a session created on one is reached through the other (307), and either
    lists both replicas' sessions."""
    import socket
    ports = []
    for _ in range(2):
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            ports.append(sock.getsockname()[1])
    a = Daemon(BIN, fresh("replica-a"), "--replica", "levelsetd-0", "--peers",
               f"levelsetd-1=http://127.0.0.1:{ports[1]}", port=ports[0])
    b = Daemon(BIN, fresh("replica-b"), "--replica", "levelsetd-1", "--peers",
               f"levelsetd-0=http://127.0.0.1:{ports[0]}", port=ports[1])
    try:
        sa = sphere_session(a, 16, "on-a")
        sb = sphere_session(b, 16, "on-b")
        check(sa["id"].startswith("levelsetd-0-s-") and sb["id"].startswith("levelsetd-1-s-"), "ids carry the replica")
        # urllib follows the 307: the session on A read through B.
        status, _, via_b = b.get(f"/api/v1/sessions/{sa['id']}")
        check(status == 200 and via_b["name"] == "on-a", f"A's session through B: {status} {via_b}")
        # A POST is answered 307 with the owner's URL (urllib does not re-send a POST; curl -L does).
        status, hdrs, body = b.post(f"/api/v1/sessions/{sa['id']}/jobs", {"op": "measure"})
        check(status == 307 and hdrs["Location"] == f"{a.url}/api/v1/sessions/{sa['id']}/jobs", f"POST via B: {status} {hdrs}")
        status, _, job = a.post(hdrs["Location"][len(a.url):], {"op": "measure"})
        check(status == 202 and job["id"].startswith("levelsetd-0-j-"), f"a job on A's session: {status} {job}")
        curl = subprocess.run(["curl", "-s", "-L", "-X", "POST", "-d", '{"op": "measure"}',
                               f"{b.url}/api/v1/sessions/{sa['id']}/jobs"], capture_output=True, text=True)
        check(json.loads(curl.stdout).get("state") in ("queued", "running", "succeeded") or "session_busy" in curl.stdout,
              f"curl -L follows the redirect with its body: {curl.stdout[:200]}")
        check(b.wait_job(job["id"])["state"] == "succeeded", "the job ran on A, followed through B")
        for d, name in ((a, "A"), (b, "B")):
            listed = d.get("/api/v1/sessions")[2]
            names = sorted(s["name"] for s in listed["sessions"])
            check(names == ["on-a", "on-b"] and listed["unreachable"] == [], f"{name} lists both: {listed}")
            local = d.get("/api/v1/sessions?local=1")[2]
            check(len(local["sessions"]) == 1, f"{name} ?local=1 lists its own only")
    finally:
        a.stop()
        b.stop()


def decode(image_bytes):
    import io
    from PIL import Image
    return Image.open(io.BytesIO(image_bytes)).convert("RGB")


def foreground(img, background=(0.13, 0.13, 0.2)):
    bg = tuple(round(c * 255) for c in background)
    return sum(1 for p in img.getdata() if max(abs(p[i] - bg[i]) for i in range(3)) > 12)


def test_frames():
    """Frames of known scenes through EGL and OSMesa: the sphere's silhouette against the
    camera's projection, the shading modes, EGL and OSMesa agreeing, size limits, the stream."""
    import math
    d = Daemon(BIN, fresh("frames-egl"), "--render", "egl")
    o = Daemon(BIN, fresh("frames-osmesa"), "--render", "osmesa", "--max-streams", "1", "--stream-fps", "5")
    try:
        check("render: egl:" in d.read_log() and "render: osmesa:" in o.read_log(), "one log line names the renderer")
        w, h = 320, 240
        images = {}
        for name, daemon in (("egl", d), ("osmesa", o)):
            s = sphere_session(daemon, 64)
            status, hdrs, png = daemon.request("GET", f"/api/v1/sessions/{s['id']}/frame?width={w}&height={h}&format=png")
            check(status == 200 and hdrs["Content-Type"] == "image/png", f"{name} frame: {status} {hdrs}")
            img = decode(png)
            check(img.size == (w, h), f"{name}: size {img.size}")
            images[name] = img
            # The camera fits the sphere's box: its bounding sphere (radius sqrt(3)) fills the
            # 40 degree field of view; the unit sphere's silhouette has this radius in pixels.
            distance = math.sqrt(3) / math.sin(math.radians(20))
            rho = (h / 2) * math.tan(math.asin(1 / distance)) / math.tan(math.radians(20))
            area = foreground(img)
            check(abs(area - math.pi * rho * rho) < 0.04 * math.pi * rho * rho,
                  f"{name}: silhouette {area} px, expected {math.pi * rho * rho:.0f}")
            # Headlight: the centre is brighter than a point near the rim.
            centre = sum(img.getpixel((w // 2, h // 2)))
            rim = sum(img.getpixel((int(w / 2 + 0.9 * rho), h // 2)))
            check(centre > rim, f"{name}: lit centre {centre} vs rim {rim}")
            counts, shades = {}, {}
            for shading in ("none", "points", "wireframe", "flat", "smooth"):
                _, _, frame = daemon.request("GET", f"/api/v1/sessions/{s['id']}/frame?width={w}&height={h}&shading={shading}&format=png")
                img_s = decode(frame)
                counts[shading] = foreground(img_s)
                shades[shading] = len(set(img_s.getdata()))
            # none draws nothing; points and wireframe are unlit (a few colours, the background and
            # the edges' blends); flat and smooth cover the silhouette with many shades.
            check(counts["none"] == 0, f"{name}: none draws nothing")
            check(all(counts[m] > 0.5 * area for m in ("points", "wireframe", "flat", "smooth")), f"{name}: coverage {counts}")
            check(abs(counts["flat"] - counts["smooth"]) < 0.02 * counts["smooth"], f"{name}: flat vs smooth {counts}")
            check(shades["points"] <= 3 and shades["wireframe"] <= 3 and shades["flat"] > 50 and shades["smooth"] > 50,
                  f"{name}: shades per mode {shades}")
            status, _, body = daemon.get(f"/api/v1/sessions/{s['id']}/frame?width=5000&height=100")
            check(status == 422, f"{name}: a 5000-pixel frame: {status}")
            status, _, body = daemon.get(f"/api/v1/sessions/{s['id']}/frame?shading=glossy")
            check(status == 422 and "shading" in body["error"]["message"], f"{name}: a bad setting: {status} {body}")
        # The overlays through HTTP, and view settings checked when they are stored.
        s = sphere_session(d, 48)
        for overlay in ("slice=z", "volume=on", "field=on", "vectors=on", "curvature=on", "boundary=on"):
            status, hdrs, png = d.request("GET", f"/api/v1/sessions/{s['id']}/frame?width=160&height=120&format=png&{overlay}")
            check(status == 200 and decode(png).size == (160, 120), f"overlay {overlay}: {status} {png[:200]!r}")
        status, _, body = d.json_request("PUT", f"/api/v1/sessions/{s['id']}/view", {"bogus": 1})
        check(status == 422 and "bogus" in json.dumps(body) or "unknown view setting" in json.dumps(body),
              f"an unknown view setting is refused when stored: {status} {body}")
        check(d.request("GET", f"/api/v1/sessions/{s['id']}/frame?width=64&height=64")[0] == 200,
              "frames still draw after a refused view")
        diff = sum(abs(a - b) for pa, pb in zip(images["egl"].getdata(), images["osmesa"].getdata()) for a, b in zip(pa, pb))
        check(diff / (w * h * 3) < 2.0, f"EGL and OSMesa differ by {diff / (w * h * 3):.2f} levels on average")
        # The MJPEG stream: new frames while a job moves the surface.
        s = sphere_session(d, 48)
        job = long_evolve(d, s["id"], steps=100000, speed="-(k1+k2)*0.02")
        import urllib.request
        frames = []
        with urllib.request.urlopen(f"{d.url}/api/v1/sessions/{s['id']}/stream?width=160&height=120", timeout=60) as r:
            check(r.headers["Content-Type"].startswith("multipart/x-mixed-replace"), f"stream type: {r.headers['Content-Type']}")
            while len(frames) < 4:
                line = r.readline()
                if line.lower().startswith(b"content-length:"):
                    n = int(line.split(b":")[1])
                    r.readline()
                    frames.append(r.read(n))
        d.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
        check(all(decode(f).size == (160, 120) for f in frames), "stream frames decode at the requested size")
        # Limits: stream_fps parts a second at most while a job moves the surface, and max_streams
        # open streams (the next gets 503).
        s = sphere_session(o, 48)
        job = long_evolve(o, s["id"], steps=100000, speed="-(k1+k2)*0.02")
        import time
        deadline = time.monotonic() + 60  # polled, not followed: an event stream would take the one slot
        while o.get(f"/api/v1/jobs/{job['id']}")[2]["progress"].get("step", 0) < 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        with urllib.request.urlopen(f"{o.url}/api/v1/sessions/{s['id']}/stream?width=64&height=64", timeout=60) as r:
            parts, start = 0, time.monotonic()
            while time.monotonic() - start < 2.0:
                if r.readline().lower().startswith(b"content-length:"):
                    parts += 1
            elapsed = time.monotonic() - start
            check(2 <= parts <= 5 * elapsed + 2, f"{parts} parts in {elapsed:.1f} s at --stream-fps 5")
            status, _, body = o.get(f"/api/v1/sessions/{s['id']}/stream")
            check(status == 503 and body["error"]["code"] == "too_many_streams", f"a second stream: {status} {body}")
        o.json_request("DELETE", f"/api/v1/jobs/{job['id']}")
        check(len(set(frames)) >= 3, f"the stream's frames change while the job runs: {len(set(frames))} distinct")
    finally:
        d.stop()
        o.stop()
    off = Daemon(BIN, fresh("frames-off"), "--render", "off")
    try:
        s = sphere_session(off, 16)
        status, _, body = off.get(f"/api/v1/sessions/{s['id']}/frame")
        check(status == 503 and body["error"]["code"] == "rendering_off", f"--render off: {status} {body}")
        check(off.get(f"/api/v1/sessions/{s['id']}/mesh?format=off")[0] == 200, "everything else works with --render off")
    finally:
        off.stop()


def test_fields():
    """Fields of speed formulas from the session (thesis table 4.1 B, J): dist from its point
    cloud and roi from its stored region of influence; frames show the ROI's points."""
    import math
    d = Daemon(BIN, fresh("fields"))
    try:
        s = sphere_session(d, 48)
        sid = s["id"]
        check(d.get(f"/api/v1/sessions/{sid}/points")[0] == 404, "no cloud: 404")
        # Without a cloud or an ROI, formulas reading them fail, naming the field.
        for speed, field in (("dist", "dist"), ("roi", "roi")):
            status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": speed, "steps": 2})
            final = d.wait_job(job["id"]) if status == 202 else job
            check(status in (202, 422) and field in json.dumps(final), f"speed {speed} without its field: {status} {final}")
        # dist: points on a sphere of radius 1.3 pull the unit sphere out: with speed = dist the
        # radius follows r' = 1.3 - r, so r(3) = 1.3 - 0.3 e^-3.
        cloud = write_sphere_cloud(os.path.join(SCRATCH, "fields-sphere13.xyz"), 20000, 1.3)
        status, _, up = upload(d, cloud, "xyz")
        check(d.json_request("PATCH", f"/api/v1/sessions/{sid}", {"points": up["id"]})[0] == 200, "attach the cloud")
        status, _, data = d.request("GET", f"/api/v1/sessions/{sid}/points")
        check(status == 200 and data == open(cloud, "rb").read(), "GET .../points gives the cloud back as uploaded")
        status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": "dist", "time": 3})
        final = d.wait_job(job["id"])
        check(final["state"] == "succeeded", f"evolve with dist: {final}")
        status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "measure"})
        volume = d.wait_job(job["id"])["result"]["volume"]
        radius, expected = (3 * volume / (4 * math.pi)) ** (1 / 3), 1.3 - 0.3 * math.exp(-3)
        check(abs(radius - expected) < 0.03, f"the front follows r' = 1.3 - r: radius {radius:.4f}, expected {expected:.4f}")
        # roi: store the current band, then a speed reading it runs; frames show its points.
        status, _, body = d.json_request("PUT", f"/api/v1/sessions/{sid}/roi", {})
        check(status == 200 and body["roi"]["active_voxels"] > 1000 and body["roi"]["version"] == body["version"],
              f"PUT roi: {status} {body}")
        status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": "0.1 * roi", "steps": 3})
        check(d.wait_job(job["id"])["state"] == "succeeded", "a speed reading roi runs once the session has one")
        frame = f"/api/v1/sessions/{sid}/frame?width=160&height=120&format=png&shading=none&cloud=off"
        check(foreground(decode(d.request("GET", frame + "&roi=on")[2])) > 500, "roi=on draws the ROI's points")
        check(foreground(decode(d.request("GET", frame)[2])) == 0, "roi off: nothing")
        status, _, body = d.json_request("PUT", f"/api/v1/sessions/{sid}/roi", {"snapshot": "vm-n-0000000000000000"})
        check(status == 404, f"an unknown snapshot: {status} {body}")
        status, _, body = d.json_request("PUT", f"/api/v1/sessions/{sid}/roi", {"band": 1})
        check(status == 422, f"an unknown field: {status} {body}")
        check(d.request("DELETE", f"/api/v1/sessions/{sid}/roi")[0] == 204, "DELETE roi")
        check(d.get(f"/api/v1/sessions/{sid}")[2]["roi"] is None, "the ROI is gone")
        check(d.get(f"/api/v1/sessions/{sid}/roi")[0] == 404, "GET roi without one: 404")
        # Another session's band as the ROI (thesis B's ROI option: a distance field computed for
        # the surface being evolved), on another grid: a unit sphere at resolution 32 whose band
        # (8 voxels) reaches the front at radius ~1.28. With speed -roi the radius follows
        # r' = 1 - r, so r(3) = 1 + (r0 - 1) e^-3.
        status, _, unit = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 32, "band": 8}})
        check(status == 201, f"the ROI's session: {status} {unit}")
        status, _, body = d.json_request("PUT", f"/api/v1/sessions/{sid}/roi", {"session": unit["id"]})
        check(status == 200 and body["roi"]["session"] == unit["id"], f"PUT roi from a session: {status} {body}")
        status, _, data = d.request("GET", f"/api/v1/sessions/{sid}/roi")
        check(status == 200 and data == d.request("GET", f"/api/v1/sessions/{unit['id']}/band")[2],
              "GET roi gives the other session's band")
        def measured_radius():
            status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "measure"})
            return (3 * d.wait_job(job["id"])["result"]["volume"] / (4 * math.pi)) ** (1 / 3)
        r0 = measured_radius()
        status, _, job = d.post(f"/api/v1/sessions/{sid}/jobs", {"op": "evolve", "speed": "-roi", "time": 3})
        check(d.wait_job(job["id"])["state"] == "succeeded", "evolve with -roi")
        after, expected = measured_radius(), 1 + (r0 - 1) * math.exp(-3)
        check(r0 > 1.2, f"the front starts outside the unit sphere: {r0:.4f}")
        check(abs(after - expected) < 0.02, f"the front follows r' = 1 - r: radius {after:.4f}, expected {expected:.4f}")
        for bad, code in (({"session": "vm-s-0000000000000000"}, 404), ({"session": 7}, 422),
                          ({"session": unit["id"], "snapshot": "x"}, 422)):
            status, _, body = d.json_request("PUT", f"/api/v1/sessions/{sid}/roi", bad)
            check(status == code, f"PUT roi {bad}: {status} {body}")
    finally:
        d.stop()


def test_concurrency():
    """64 clients creating sessions, submitting jobs, polling and holding event streams."""
    d = Daemon(BIN, fresh("concurrency"), "--max-queued-jobs", "256")
    errors = []

    def client(i):
        try:
            status, _, s = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 16}})
            if status != 201:
                return f"create {status}"
            status, _, job = d.post(f"/api/v1/sessions/{s['id']}/jobs", {"op": "redistance"})
            if status != 202:
                return f"submit {status} {job}"
            if i % 2:
                final = d.wait_job(job["id"], timeout=300)
            else:
                for _ in range(200):
                    final = d.get(f"/api/v1/jobs/{job['id']}")[2]
                    if final["state"] not in ("queued", "running"):
                        break
                    d.events(f"/api/v1/jobs/{job['id']}/events", until=lambda e: e[1] == "done", timeout=60)
            if final["state"] != "succeeded":
                return f"job {final['state']}"
            for _ in range(5):
                if d.get(f"/api/v1/sessions/{s['id']}")[0] != 200:
                    return "poll"
            return None
        except Exception as e:  # noqa: BLE001
            return repr(e)

    try:
        with concurrent.futures.ThreadPoolExecutor(64) as pool:
            results = list(pool.map(client, range(64)))
        errors = [r for r in results if r]
        check(not errors, f"{len(errors)} clients failed: {errors[:5]}")
        status, _, m = d.request("GET", "/metrics")
        check(b"levelset_sessions 64" in m, "64 sessions counted")
        healthy(d)
    finally:
        d.stop()


if __name__ == "__main__":
    name = sys.argv[4]
    os.makedirs(SCRATCH, exist_ok=True)
    t0 = time.monotonic()
    globals()["test_" + name]()
    print(f"daemon_api {name}: passed in {time.monotonic() - t0:.1f} s")
