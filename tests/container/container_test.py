#!/usr/bin/python3
"""make container-test (issue 18): the real image from deploy/Dockerfile, built and run here.

dockerd on its own socket and data root; a bookworm base from debootstrap and this machine's apt
mirror (no registry is reachable); `docker build --build-arg BASE=...`; then the image runs with
no display, a named volume, a token secret file, a mounted server.conf, LEVELSET_* variables and
the port published on 127.0.0.1 only. Over HTTP: health, an upload (a generated point cloud), a
reconstruction job, PNG and JPEG frames (EGL surfaceless, no display), a mesh download, Docker's
HEALTHCHECK; `docker stop` (SIGTERM) during a job exits 0 within the shutdown deadline; a new
container on the same volume has the session back. Prints each phase's time, the image size and
the time from `docker run` to /readyz. Removes its containers, volume and images and stops its
dockerd, also on failure. Exits non-zero with the reason on any failure (a missing tool too).

Usage: container_test.py        (as root; make container-test installs the tools first)
"""
import http.client
import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import traceback
import urllib.error
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "integration"))
from daemon_harness import Daemon, off_topology, upload  # noqa: E402
from docker_env import BASE_TAG, CACHE, ROOT, Dockerd, Failure, base_image, log  # noqa: E402
from image_check import foreground, jpeg_size, png_rgb  # noqa: E402
from torus_points import torus_xyz  # noqa: E402

TAG = f"levelset-{os.getpid()}"
IMAGE = f"localhost/{TAG}:test"
TOKEN = "container-test-" + os.urandom(12).hex()
DEADLINE = 10           # LEVELSET_SHUTDOWN_DEADLINE given to the container
BACKGROUND = (33, 33, 51)  # the frames' default background, (0.13, 0.13, 0.2) in 0-255


def check(cond, what):
    if not cond:
        raise Failure(what)


class Remote(Daemon):
    """daemon_harness's HTTP helpers against a daemon in a container, with the bearer token."""

    def __init__(self, url, token):
        self.url, self.token = url, token

    def request(self, method, path, body=None, headers=None, timeout=60):
        return super().request(method, path, body, {"Authorization": f"Bearer {self.token}", **(headers or {})}, timeout)

    def events(self, path, until=None, timeout=120, headers=None):
        return super().events(path, until, timeout, {"Authorization": f"Bearer {self.token}", **(headers or {})})


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Phases:
    def __init__(self):
        self.rows = []

    def add(self, name, seconds, note=""):
        self.rows.append((name, seconds, note))
        log(f"phase {name}: {seconds:.1f} s {note}".rstrip())

    def report(self):
        log("---- phase timings")
        for name, seconds, note in self.rows:
            print(f"  {name:<48} {seconds:8.1f} s  {note}", flush=True)


class Run:
    """One `docker run` of the image; wait_ready() polls /readyz on the published port."""

    def __init__(self, dockerd, name, port, volume, secrets_dir):
        self.dockerd, self.name, self.port = dockerd, name, port
        self.t0 = time.monotonic()
        dockerd.run("run", "-d", "--name", name,
                    "-p", f"127.0.0.1:{port}:8080",
                    "-v", f"{volume}:/var/lib/levelset",
                    "-v", f"{secrets_dir}/tokens:/run/secrets/levelset-tokens:ro",
                    "-v", f"{secrets_dir}/server.conf:/etc/levelset/server.conf:ro",
                    "-e", f"LEVELSET_SHUTDOWN_DEADLINE={DEADLINE}",
                    "-e", "LEVELSET_MAX_QUEUED_JOBS=9",
                    "--stop-timeout", str(DEADLINE + 10),
                    IMAGE, capture=True)
        self.url = f"http://127.0.0.1:{port}"

    def state(self):
        return json.loads(self.dockerd.out("inspect", "-f", "{{json .State}}", self.name))

    def logs(self):
        r = self.dockerd.run("logs", self.name, check=False, capture=True)
        return (r.stdout + r.stderr).decode("utf-8", "replace")

    def wait_ready(self, timeout=60):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                with urllib.request.urlopen(self.url + "/readyz", timeout=2) as r:
                    if r.status == 200:
                        return time.monotonic() - self.t0
            except (OSError, http.client.HTTPException):
                pass  # not listening yet (docker-proxy accepts and closes), or 503 while starting
            if not self.state()["Running"]:
                raise Failure(f"container {self.name} exited: {self.state()}\n{self.logs()[-3000:]}")
            time.sleep(0.1)
        raise Failure(f"/readyz not 200 within {timeout} s\n{self.logs()[-3000:]}")

    def stop(self):
        """docker stop (SIGTERM, SIGKILL after --stop-timeout); returns (exit code, seconds)."""
        t0 = time.monotonic()
        self.dockerd.run("stop", self.name, capture=True)
        seconds = time.monotonic() - t0
        state = self.state()
        check(not state["Running"], f"{self.name} still running after docker stop")
        return state["ExitCode"], seconds


def build_image(dockerd, phases):
    base, debootstrap_s, import_s = base_image(dockerd)
    phases.add("base image: debootstrap", debootstrap_s, "(cached tarball under build/container)" if debootstrap_s == 0 else "")
    phases.add("base image: docker import", import_s)
    build_log = os.path.join(CACHE, "image-build.log")
    t0 = time.monotonic()
    with open(build_log, "wb") as f:
        r = subprocess.run([dockerd.client, "-H", dockerd.host, "build", "--force-rm", "-f", os.path.join(ROOT, "deploy", "Dockerfile"),
                            "--build-arg", f"BASE={base}", "-t", IMAGE, ROOT], stdout=f, stderr=subprocess.STDOUT)
    if r.returncode != 0:
        with open(build_log, "rb") as f:
            tail = f.read().decode("utf-8", "replace")[-6000:]
        raise Failure(f"docker build failed ({r.returncode}); the end of {build_log}:\n{tail}")
    phases.add("image build", time.monotonic() - t0, f"(log: {os.path.relpath(build_log, ROOT)})")
    size = int(dockerd.out("image", "inspect", "-f", "{{.Size}}", IMAGE))
    config = json.loads(dockerd.out("image", "inspect", "-f", "{{json .Config}}", IMAGE))
    log(f"image {IMAGE}: {size / 1e6:.0f} MB ({size} bytes), user {config['User']!r}")
    check(config["User"] not in ("", "root", "0"), f"the image runs as root: {config['User']!r}")
    check(config.get("Healthcheck") and "/healthz" in " ".join(config["Healthcheck"]["Test"]), "HEALTHCHECK on /healthz")
    # Every shared library of both binaries resolves in the final stage (runtime group only).
    for binary in ("levelsetd", "levelsetctl"):
        ldd = dockerd.out("run", "--rm", "--entrypoint", "ldd", IMAGE, f"/usr/local/bin/{binary}")
        check("not found" not in ldd, f"{binary} in the image misses libraries:\n{ldd}")
    return size


def scenario(dockerd, phases, secrets_dir):
    volume = f"{TAG}-data"
    dockerd.run("volume", "create", volume, capture=True)
    port = free_port()
    first = Run(dockerd, f"{TAG}-a", port, volume, secrets_dir)
    phases.add("docker run -> /readyz", first.wait_ready())
    d = Remote(first.url, TOKEN)

    status, _, body = d.get("/healthz")
    check(status == 200 and body["status"] == "ok", f"/healthz: {status} {body}")
    status, _, body = Daemon.json_request(Remote(first.url, "wrong-token"), "GET", "/api/v1/sessions")
    check(status == 401, f"a wrong token is refused beyond loopback: {status} {body}")
    status, _, api = d.get("/api/v1")
    check(status == 200 and api["limits"]["max_sessions"] == 17 and api["limits"]["max_queued_jobs"] == 9,
          f"settings from the mounted server.conf (max_sessions 17) and LEVELSET_* (max_queued_jobs 9): {api.get('limits')}")
    uid = dockerd.out("exec", first.name, "id", "-u")
    check(uid not in ("", "0"), f"the daemon runs as a non-root user: uid {uid!r}")
    logs = first.logs()
    check("render: egl" in logs, f"the daemon renders through EGL with no display:\n{logs[-2000:]}")

    # Upload a generated point cloud, reconstruct it.
    t0 = time.monotonic()
    points = os.path.join(secrets_dir, "torus.xyz")
    with open(points, "wb") as f:
        f.write(torus_xyz(10000))
    status, _, up = upload(d, points, "xyz")
    check(status == 201 and up["kind"] == "points" and up["summary"]["points"] == 10000, f"upload: {status} {up}")
    status, _, job = d.post("/api/v1/sessions", {"upload": up["id"], "name": "torus", "raster": {"resolution": 64}})
    check(status == 202, f"reconstruction job: {status} {job}")
    final = d.wait_job(job["id"], timeout=300)
    check(final["state"] == "succeeded", f"reconstruction: {final}")
    sid = final["result"]["session"]
    phases.add("upload + reconstruction job", time.monotonic() - t0)

    # Frames with no display: a PNG decoded in full, a JPEG's header; the requested sizes.
    status, hdrs, png = d.request("GET", f"/api/v1/sessions/{sid}/frame?width=320&height=240&format=png")
    check(status == 200 and hdrs.get("Content-Type") == "image/png", f"PNG frame: {status} {hdrs}")
    w, h, rows = png_rgb(png)
    drawn = foreground(rows, BACKGROUND)
    check((w, h) == (320, 240) and 0.05 * w * h < drawn < 0.9 * w * h, f"PNG frame {w}x{h}, {drawn} px drawn")
    status, hdrs, jpg = d.request("GET", f"/api/v1/sessions/{sid}/frame?width=200&height=150&format=jpeg")
    check(status == 200 and hdrs.get("Content-Type") == "image/jpeg", f"JPEG frame: {status} {hdrs}")
    check(jpeg_size(jpg) == (200, 150, 3), f"JPEG frame header: {jpeg_size(jpg)}")

    # The mesh: the torus's topology.
    status, hdrs, mesh = d.request("GET", f"/api/v1/sessions/{sid}/mesh?format=off")
    check(status == 200 and hdrs.get("ETag"), f"mesh download: {status}")
    topo = off_topology(mesh.decode())
    check(topo[2] and topo[3] == 1 and topo[4] == 1, f"the torus: watertight, genus 1, one component: {topo}")

    # Docker's HEALTHCHECK (bash /dev/tcp in the image) reports healthy.
    deadline = time.monotonic() + 60
    while first.state().get("Health", {}).get("Status") != "healthy" and time.monotonic() < deadline:
        time.sleep(0.5)
    health = first.state().get("Health", {})
    check(health.get("Status") == "healthy", f"HEALTHCHECK: {json.dumps(health)[-1500:]}")
    phases.add("docker run -> HEALTHCHECK healthy", time.monotonic() - first.t0, "(probes every 10 s)")

    # SIGTERM during a running job: exit 0 within the deadline, the job checkpointed.
    status, _, sphere = d.post("/api/v1/sessions", {"primitive": "sphere", "raster": {"resolution": 64}, "name": "sphere"})
    check(status == 201, f"sphere session: {status} {sphere}")
    status, _, long_job = d.post(f"/api/v1/sessions/{sphere['id']}/jobs",
                                 {"op": "evolve", "speed": "-(k1+k2)", "steps": 100000, "report_every": 0})
    check(status == 202, f"long job: {status} {long_job}")
    d.events(f"/api/v1/jobs/{long_job['id']}/events", timeout=60,
             until=lambda e: e[1] == "progress" and e[2].get("step", 0) >= 5)
    rc, seconds = first.stop()
    phases.add("docker stop (SIGTERM, job running)", seconds)
    check(rc == 0 and seconds < DEADLINE, f"docker stop: exit {rc} after {seconds:.1f} s (deadline {DEADLINE} s)\n"
                                          f"{first.logs()[-2000:]}")

    # A new container on the same volume: the sessions are back, the mesh unchanged.
    second = Run(dockerd, f"{TAG}-b", port, volume, secrets_dir)
    phases.add("restart on the volume -> /readyz", second.wait_ready())
    d = Remote(second.url, TOKEN)
    sessions = {s["id"]: s for s in d.get("/api/v1/sessions")[2]["sessions"]}
    check(set(sessions) == {sid, sphere["id"]} and sessions[sid]["name"] == "torus", f"sessions back: {sessions}")
    status, hdrs2, mesh2 = d.request("GET", f"/api/v1/sessions/{sid}/mesh?format=off")
    check(status == 200 and mesh2 == mesh, "the torus's mesh after the restart is the same")
    j = d.get(f"/api/v1/jobs/{long_job['id']}")[2]
    check(j["state"] == "interrupted", f"the job cut by SIGTERM is interrupted (resumable): {j['state']}")
    rc, seconds = second.stop()
    check(rc == 0 and seconds < DEADLINE, f"second docker stop: exit {rc} after {seconds:.1f} s")
    return [first.name, second.name], volume


def main():
    phases = Phases()
    dockerd, containers, volume = None, [f"{TAG}-a", f"{TAG}-b"], f"{TAG}-data"
    failed = None
    t_all = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="levelset-container-") as secrets_dir:
        os.chmod(secrets_dir, 0o755)
        with open(os.path.join(secrets_dir, "tokens"), "w") as f:
            f.write(f"{TOKEN} rw\n")
        with open(os.path.join(ROOT, "configs", "server.conf")) as f:
            conf = f.read().replace("max_sessions = 256", "max_sessions = 17")
        check("max_sessions = 17" in conf, "configs/server.conf sets max_sessions = 256")
        with open(os.path.join(secrets_dir, "server.conf"), "w") as f:
            f.write(conf)
        for name in ("tokens", "server.conf"):
            os.chmod(os.path.join(secrets_dir, name), 0o644)  # the image's user (uid 10001) reads them
        try:
            t0 = time.monotonic()
            dockerd = Dockerd()
            phases.add("dockerd start", time.monotonic() - t0)
            size = build_image(dockerd, phases)
            scenario(dockerd, phases, secrets_dir)
            log(f"image size: {size / 1e6:.0f} MB")
        except Failure as e:
            failed = str(e)
        except Exception:  # an unexpected error is a failure too, with its traceback
            failed = traceback.format_exc()
        finally:
            if dockerd is not None:
                t0 = time.monotonic()
                for c in containers:
                    dockerd.run("rm", "-f", c, check=False, capture=True)
                dockerd.run("volume", "rm", "-f", volume, check=False, capture=True)
                for image in (IMAGE, BASE_TAG):
                    dockerd.run("rmi", "-f", image, check=False, capture=True)
                dockerd.run("image", "prune", "-a", "-f", check=False, capture=True)  # the build stage's image
                left = dockerd.out("ps", "-aq", check=False) + dockerd.out("images", "-aq", check=False)
                phases.add("clean-up: containers, volume, images", time.monotonic() - t0)
                t0 = time.monotonic()
                try:
                    dockerd.stop()
                except Failure as e:
                    failed = failed or str(e)
                phases.add("clean-up: dockerd stopped, its data root removed", time.monotonic() - t0)
                if left.strip():
                    failed = failed or f"left behind in dockerd: {left}"
    phases.add("total", time.monotonic() - t_all)
    phases.report()
    if failed:
        print(f"container-test: FAILED: {failed}", file=sys.stderr, flush=True)
        return 1
    print("container-test: passed", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
