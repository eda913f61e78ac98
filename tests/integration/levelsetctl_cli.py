#!/usr/bin/python3
"""levelsetctl against a real levelsetd serve on a free loopback port (real HTTP, real binaries).

Usage: levelsetctl_cli.py LEVELSETD LEVELSETCTL SCRATCH CGAL_DATA JOBS_DIR SCENARIO

Scenarios:
  jobs      `levelsetctl run` of every shipped job file (JOBS_DIR/*.conf, at the reduced sizes
            below) writes the same files as `levelsetd run` with the same --set: mesh, .lsg and
            every other output byte for byte (the .log and .stats.json carry timings; the daemon's
            jobs run on half the threads levelsetd run uses); a job
            file naming local input files (relative and absolute) has them uploaded.
  commands  exit codes (a failing job 1, an unknown session 1, a malformed job file 2, usage 2,
            no server 3); `jobs wait` shows progress (lines, and a bar on a terminal) and
            returns 0 on success, non-zero for a cancelled job; SIGTERM to `run` cancels its job;
            a wait through a proxy that cuts
            the event stream resumes with Last-Event-ID (no log line lost or repeated); uploads
            of malformed files are refused with the server's message; downloads equal the API's;
            the README's levelsetctl walk-through runs as written.
Missing binaries, data or job sizes fail the test; nothing is skipped.
"""
import filecmp
import json
import os
import pty
import re
import select
import shutil
import socket
import subprocess
import sys
import threading
import time
import urllib.request

# The reduced sizes of tests/integration/check_job.py's first run of each job, with two
# exceptions to keep this test near a minute: the liver at downsample 8 (37 s at its default 4)
# and the bunny and kitten with their outputs on (check_job turns them off; here they are what
# is compared). A shipped job without an entry fails the test.
SIZES = {
    "evolve_dumbbell": ["raster.resolution=48"],
    "offset_knot": ["raster.resolution=64"],
    "fair_elephant": ["raster.resolution=96"],
    "minmax_elephant": ["raster.resolution=96"],
    "csg_knot_sphere": ["raster.resolution=64"],
    "path_sphere": [],
    "voronoi_seeds": [],
    "reconstruct_knot": ["raster.resolution=128"],
    "segment_liver": ["input.downsample=8"],
    "reconstruct_bunny": ["raster.resolution=128"],
    "reconstruct_kitten": [],
}
TIMED_FILES = (".log", ".stats.json")


class Failure(Exception):
    pass


def fail(msg):
    raise Failure(msg)


def check(cond, msg):
    if not cond:
        fail(msg)


class Daemon:
    def __init__(self, binary, data_dir, env, flags=()):
        self.stderr = data_dir + ".stderr"
        self.proc = subprocess.Popen([binary, "serve", "--port", "0", "--data", data_dir, *flags],
                                     stdout=subprocess.PIPE, stderr=open(self.stderr, "w"), text=True, env=env)
        deadline = time.time() + 30
        line = ""
        while time.time() < deadline:
            line = self.proc.stdout.readline()
            m = re.match(r"levelsetd listening on (http://[^:]+:\d+)", line)
            if m:
                self.url = m.group(1)
                threading.Thread(target=self.proc.stdout.read, daemon=True).start()  # drain
                return
            if not line and self.proc.poll() is not None:
                break
        self.stop()
        fail(f"levelsetd serve did not start (last line {line!r}; see {data_dir}.stderr)")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


class Ctx:
    def __init__(self, levelsetd, ctl, scratch, env, url):
        self.levelsetd, self.ctl, self.scratch, self.env, self.url = levelsetd, ctl, scratch, env, url

    def ctl_run(self, args, server=None, cwd=None, timeout=300):
        cmd = [self.ctl, "--server", server or self.url] + args
        return subprocess.run(cmd, capture_output=True, text=True, env=self.env, cwd=cwd or self.scratch,
                              timeout=timeout)

    def ok(self, args, **kw):
        p = self.ctl_run(args, **kw)
        check(p.returncode == 0, f"levelsetctl {' '.join(args)} -> {p.returncode}\n{p.stdout}\n{p.stderr}")
        return p

    def refused(self, args, rc, code, **kw):
        """Exit code `rc` with one error line 'levelsetctl: CODE: MESSAGE' on stderr; the message."""
        p = self.ctl_run(args, **kw)
        check(p.returncode == rc, f"levelsetctl {' '.join(args)}: exit {p.returncode}, expected {rc}\n{p.stderr}")
        lines = [l for l in p.stderr.splitlines() if l.startswith("levelsetctl: ")]
        check(len(lines) == 1, f"levelsetctl {' '.join(args)}: expected one error line, got {p.stderr!r}")
        m = re.match(r"levelsetctl: ([a-z0-9_]+): (.+)$", lines[0])
        check(m is not None and m.group(1) == code, f"levelsetctl {' '.join(args)}: expected code {code}: {lines[0]!r}")
        return m.group(2)

    def http(self, method, path, body=None, raw=False):
        data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
        req = urllib.request.Request(self.url + path, data=data, method=method)
        try:
            with urllib.request.urlopen(req, timeout=60) as r:
                out = r.read()
                return r.status, (out if raw else json.loads(out or b"null"))
        except urllib.error.HTTPError as e:
            return e.code, json.loads(e.read() or b"null")


# ---- scenario: jobs ------------------------------------------------------------------------


def compare_runs(ctx, name, local_dir, ctl_dir, ctl_stdout):
    local = sorted(os.listdir(local_dir))
    remote = sorted(f for f in os.listdir(ctl_dir) if ".part-" not in f)
    check(local == remote, f"{name}: levelsetd run wrote {local}, levelsetctl run {remote}")
    compared = [f for f in local if not f.endswith(TIMED_FILES)]
    check(compared, f"{name}: no output to compare")
    for f in compared:
        check(filecmp.cmp(os.path.join(local_dir, f), os.path.join(ctl_dir, f), shallow=False),
              f"{name}: {f} differs between levelsetd run and levelsetctl run")
    stem = name[: -len(".conf")] if name.endswith(".conf") else name
    stats = json.load(open(os.path.join(ctl_dir, stem + ".stats.json")))
    check(sorted(os.path.basename(p) for p in stats["outputs"]) == local, f"{name}: stats outputs {stats['outputs']}")
    for p in stats["outputs"]:
        check(os.path.exists(os.path.join(ctx.scratch, p)), f"{name}: stats output {p} is not a local file")
    log_lines = [l for l in ctl_stdout.splitlines() if l.startswith("[")]
    local_log = [l[12:] for l in open(os.path.join(local_dir, stem + ".log")).read().splitlines()]
    check([l[12:] for l in log_lines][:1] == local_log[:1] and len(log_lines) == len(local_log),
          f"{name}: printed log {log_lines[:3]}... vs levelsetd's {local_log[:3]}...")
    return compared


def run_pair(ctx, job, sets, tag):
    name = os.path.basename(job)
    set_args = [a for s in sets for a in ("--set", s)]
    local_dir, ctl_dir = f"local_{tag}", f"ctl_{tag}"
    t0 = time.time()
    p = subprocess.run([ctx.levelsetd, "run", job, "-o", local_dir, "-q"] + set_args, capture_output=True, text=True,
                       env=ctx.env, cwd=ctx.scratch)
    check(p.returncode == 0, f"levelsetd run {job} failed: {p.stdout}\n{p.stderr}")
    t1 = time.time()
    p = ctx.ok(["run", job, "-o", ctl_dir] + set_args)
    t2 = time.time()
    files = compare_runs(ctx, name, os.path.join(ctx.scratch, local_dir), os.path.join(ctx.scratch, ctl_dir), p.stdout)
    print(f"  {name}: levelsetd run {t1 - t0:.1f} s, levelsetctl run {t2 - t1:.1f} s; identical: {' '.join(files)}",
          flush=True)
    return p


def scenario_jobs(ctx, cgal, jobs_dir):
    jobs = sorted(f for f in os.listdir(jobs_dir) if f.endswith(".conf"))
    check(jobs, f"no job files in {jobs_dir}")
    missing = [j for j in jobs if j[:-5] not in SIZES]
    check(not missing, f"no reduced size for {missing}: add them to SIZES in {__file__}")
    for j in jobs:
        run_pair(ctx, os.path.join(jobs_dir, j), SIZES[j[:-5]], j[:-5])

    # Local inputs: a relative mesh named twice (uploaded once) and an absolute .lsg.
    inputs = os.path.join(ctx.scratch, "inputs")
    os.makedirs(os.path.join(inputs, "sub"), exist_ok=True)
    shutil.copy(os.path.join(cgal, "meshes", "elephant.off"), os.path.join(inputs, "sub", "elephant.off"))
    job = os.path.join(inputs, "local_csg.conf")
    open(job, "w").write("job = csg\ninput { mesh = sub/elephant.off }\nraster { resolution = 48 }\n"
                         "csg {\n  op = difference\n  operand { mesh = \"sub/elephant.off\"  translate = (0.05, 0, 0) }\n}\n")
    p = run_pair(ctx, job, [], "local_csg")
    uploads = re.findall(r"^uploaded (.+) as (\S+)$", p.stderr, re.M)
    check(len(uploads) == 1 and uploads[0][0].endswith("sub/elephant.off"), f"one upload expected: {p.stderr}")
    lsg = os.path.join(ctx.scratch, "local_evolve_dumbbell", "evolve_dumbbell.lsg")
    job = os.path.join(inputs, "local_offset.conf")
    open(job, "w").write(f"job = offset\ninput {{ lsg = \"{lsg}\" }}\noffset {{ distance = 0.05  back = no }}\n")
    run_pair(ctx, job, [], "local_offset")
    # A --set naming a local file is uploaded too.
    run_pair(ctx, job, [f"input.lsg={os.path.join(ctx.scratch, 'local_offset_knot', 'offset_knot.lsg')}"],
             "local_offset_set")


# ---- scenario: commands --------------------------------------------------------------------


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class CuttingProxy:
    """Forwards loopback TCP to the daemon; the first event stream is cut after `cut` bytes of
    its response (the connection drops mid-stream)."""

    def __init__(self, target_port, cut):
        self.target, self.cut, self.cuts = target_port, cut, 0
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(16)
        self.port = self.sock.getsockname()[1]
        threading.Thread(target=self.accept, daemon=True).start()

    def accept(self):
        while True:
            try:
                c, _ = self.sock.accept()
            except OSError:
                return
            threading.Thread(target=self.serve, args=(c,), daemon=True).start()

    def serve(self, c):
        u = socket.create_connection(("127.0.0.1", self.target))
        head = c.recv(65536)
        cut = self.cut if (b"/events" in head.split(b"\r\n", 1)[0] and self.cuts == 0) else None
        if cut is not None:
            self.cuts += 1
        u.sendall(head)
        sent = 0
        try:
            while True:
                r, _, _ = select.select([c, u], [], [], 30)
                if not r:
                    break
                if c in r:
                    d = c.recv(65536)
                    if not d:
                        break
                    u.sendall(d)
                if u in r:
                    d = u.recv(65536)
                    if not d:
                        break
                    if cut is not None and sent + len(d) >= cut:
                        c.sendall(d[: max(0, cut - sent)])
                        break
                    c.sendall(d)
                    sent += len(d)
        except OSError:
            pass
        for s in (c, u):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            s.close()


def evolve_job(ctx, session, steps):
    return ctx.ok(["jobs", "submit", session, "--op", "evolve", "--param", "speed=-H", "--param", f"steps={steps}",
                   "--param", "report_every=25"]).stdout.strip()


def step_lines(text):
    return [int(m) for m in re.findall(r"^\[ *[0-9.]+ s\] step (\d+) ", text, re.M)]


def readme_block(ctx, readme, jobs_dir):
    """The README's levelsetctl walk-through, run as written (bash -euo pipefail) with
    levelsetctl on PATH, from a folder where configs/ is the repository's."""
    text = open(readme).read()
    m = re.search(r"The same with `levelsetctl`.*?```sh\n(.*?)```", text, re.S)
    check(m is not None, f"no levelsetctl walk-through in {readme}")
    work = os.path.join(ctx.scratch, "readme")
    os.makedirs(work)
    os.symlink(os.path.dirname(jobs_dir), os.path.join(work, "configs"))
    env = dict(ctx.env, LEVELSET_URL=ctx.url, PATH=os.path.dirname(ctx.ctl) + os.pathsep + ctx.env["PATH"])
    p = subprocess.run(["bash", "-euo", "pipefail", "-c", m.group(1)], cwd=work, capture_output=True, text=True,
                       env=env, timeout=240)
    check(p.returncode == 0, f"the README's levelsetctl block failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    check(p.stdout.rstrip().endswith("exit 1") and "levelsetctl: " in p.stderr, f"README block: {p.stdout[-200:]}")
    for f in ("torus.ply", "kitten.off", "out/offset_knot.ply", "out/offset_knot.lsg"):
        check(os.path.getsize(os.path.join(work, f)) > 0, f"README block: no {f}")
    check(json.load(open(os.path.join(work, "evolve.json")))["evolution"]["steps"] == 60, "README block: evolve.json")


def scenario_commands(ctx, cgal, readme, jobs_dir):
    readme_block(ctx, readme, jobs_dir)

    # Usage, no server.
    ctx.refused([], 2, "usage")
    ctx.refused(["jobs", "submit"], 2, "usage")
    ctx.refused(["download", "mesh", "x", "-o", "x.vtk"], 2, "unknown_format")
    ctx.refused(["sessions", "list"], 3, "cannot_connect", server=f"http://127.0.0.1:{free_port()}")
    ctx.refused(["run", os.path.join(ctx.scratch, "none.conf")], 4, "io_error")
    open(os.path.join(ctx.scratch, "broken.conf"), "w").write("job = offset\ninput { shape = knot\n")
    msg = ctx.refused(["run", "broken.conf"], 2, "invalid_job")
    check("broken.conf:" in msg, msg)

    # Sessions, downloads equal to the API's bytes.
    sid = ctx.ok(["sessions", "create", "--primitive", "sphere", "--resolution", "48", "--name", "ball"]).stdout.strip()
    check(re.fullmatch(r"[a-z0-9-]+-s-[0-9a-f]{16}", sid) is not None, f"session id {sid!r}")
    check(sid in ctx.ok(["sessions", "list"]).stdout, "sessions list lacks the session")
    check(json.loads(ctx.ok(["sessions", "show", sid]).stdout)["name"] == "ball", "sessions show")
    ctx.ok(["download", "mesh", sid, "-o", "ball.obj", "--method", "nets"])
    ctx.ok(["download", "band", sid, "-o", "ball.lsg"])
    for f, path in (("ball.obj", f"/api/v1/sessions/{sid}/mesh?format=obj&method=nets"),
                    ("ball.lsg", f"/api/v1/sessions/{sid}/band")):
        status, body = ctx.http("GET", path, raw=True)
        check(status == 200 and open(os.path.join(ctx.scratch, f), "rb").read() == body, f"download {f} differs")
    check(not [f for f in os.listdir(ctx.scratch) if ".part-" in f], "temporary download files left")
    ctx.refused(["download", "band", "vm-s-0123456789abcdef", "-o", "nothing.lsg"], 1, "not_found")
    check(not os.path.exists(os.path.join(ctx.scratch, "nothing.lsg")), "a refused download left a file")
    snap = json.loads(ctx.ok(["sessions", "snapshot", sid, "--name", "first"]).stdout)
    check(snap.get("name") == "first", f"snapshot {snap}")
    # The region of influence: another session's band, downloaded as the API gives it; cleared.
    other = ctx.ok(["sessions", "create", "--primitive", "torus", "--resolution", "32"]).stdout.strip()
    shown = json.loads(ctx.ok(["sessions", "roi", sid, "--from-session", other]).stdout)
    check(shown["roi"]["session"] == other, f"sessions roi --from-session: {shown['roi']}")
    ctx.ok(["download", "roi", sid, "-o", "roi.lsg"])
    status, body = ctx.http("GET", f"/api/v1/sessions/{other}/band", raw=True)
    check(open(os.path.join(ctx.scratch, "roi.lsg"), "rb").read() == body, "download roi is not the torus's band")
    check(json.loads(ctx.ok(["sessions", "roi", sid, "--snapshot", snap["id"]]).stdout)["roi"]["snapshot"] == snap["id"],
          "sessions roi --snapshot")
    check(json.loads(ctx.ok(["sessions", "roi", sid, "--clear"]).stdout)["roi"] is None, "sessions roi --clear")
    ctx.refused(["download", "roi", sid, "-o", "none.lsg"], 1, "not_found")
    ctx.refused(["sessions", "roi", sid, "--clear", "--snapshot", snap["id"]], 2, "usage")
    ctx.refused(["download", "points", sid, "-o", "none.xyz"], 1, "not_found")

    # An unknown session, a failing job, a refused parameter.
    msg = ctx.refused(["jobs", "submit", "vm-s-0123456789abcdef", "--op", "offset", "--param", "distance=0.1"], 1,
                      "not_found")
    status, body = ctx.http("POST", "/api/v1/sessions/vm-s-0123456789abcdef/jobs", {"op": "offset", "distance": 0.1})
    check(status == 404 and msg == body["error"]["message"], f"{msg!r} vs {body}")
    status, body = ctx.http("POST", f"/api/v1/sessions/{sid}/jobs", {"op": "nonsense"})
    msg = ctx.refused(["jobs", "submit", sid, "--op", "nonsense"], 1, body["error"]["code"])
    check(status == 422 and msg == body["error"]["message"], f"{msg!r} vs {body}")
    open(os.path.join(ctx.scratch, "fails.conf"), "w").write("job = offset\ninput { mesh = cgal:meshes/no_such_mesh.off }\n")
    msg = ctx.refused(["run", "fails.conf", "-o", "fails_out"], 1, "io_error")
    check("no_such_mesh.off" in msg, msg)

    # jobs wait: plain progress lines on a pipe, exit 0, the result on stdout.
    jid = evolve_job(ctx, sid, 150)
    p = ctx.ok(["jobs", "wait", jid])
    progress = [int(m) for m in re.findall(r"^progress: (\d+)%", p.stderr, re.M)]
    check(len(progress) >= 3 and progress == sorted(progress) and progress[-1] == 100, f"progress lines: {p.stderr}")
    check(step_lines(p.stderr) == list(range(25, 151, 25)), f"log lines: {p.stderr}")
    check(json.loads(p.stdout)["evolution"]["steps"] == 150, p.stdout)
    # ... a bar on a terminal.
    jid = evolve_job(ctx, sid, 100)
    pid, fd = pty.fork()
    if pid == 0:
        os.execve(ctx.ctl, [ctx.ctl, "--server", ctx.url, "jobs", "wait", jid], ctx.env)
    out = b""
    while True:
        try:
            d = os.read(fd, 65536)
        except OSError:
            break
        if not d:
            break
        out += d
    _, st = os.waitpid(pid, 0)
    text = out.decode(errors="replace")
    check(os.waitstatus_to_exitcode(st) == 0, f"jobs wait on a terminal: {text}")
    check(re.search(r"\r\[#+ *\] +\d+%", text) is not None and "progress:" not in text, f"no bar: {text[:400]!r}")
    # ... submit --wait, and a cancelled job's wait is not 0.
    p = ctx.ok(["jobs", "submit", sid, "--op", "evolve", "--param", "speed=-H", "--param", "steps=20", "--wait"])
    check(json.loads(p.stdout)["evolution"]["steps"] == 20, p.stdout)
    jid = evolve_job(ctx, sid, 5000)
    time.sleep(0.5)
    ctx.ok(["jobs", "cancel", jid])
    ctx.refused(["jobs", "wait", jid], 1, "job_cancelled")
    ctx.refused(["jobs", "cancel", jid], 1, "conflict")
    check(jid in ctx.ok(["jobs", "list"]).stdout, "jobs list lacks the job")
    check(json.loads(ctx.ok(["jobs", "show", jid]).stdout)["state"] == "cancelled", "jobs show")
    # ... stop keeps the state reached and succeeds.
    jid = evolve_job(ctx, sid, 5000)
    time.sleep(0.8)
    ctx.ok(["jobs", "stop", jid])
    p = ctx.ok(["jobs", "wait", jid])
    check(json.loads(p.stdout)["stopped"] is True, p.stdout)

    # SIGTERM to `run` cancels its job on the server (a workflow system killing the client).
    long_job = os.path.join(ctx.scratch, "long.conf")
    open(long_job, "w").write("job = fair\ninput { shape = dumbbell }\nraster { resolution = 64 }\n"
                              "fair { flow = volume-preserving  steps = 1000000 }\n")
    before = {j["id"] for j in ctx.http("GET", "/api/v1/jobs")[1]["jobs"]}
    proc = subprocess.Popen([ctx.ctl, "--server", ctx.url, "run", long_job, "-o", "long_out"], cwd=ctx.scratch,
                            env=ctx.env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 30
    running = []
    while not running and time.time() < deadline:
        time.sleep(0.1)
        running = [j["id"] for j in ctx.http("GET", "/api/v1/jobs")[1]["jobs"]
                   if j["id"] not in before and j["state"] == "running"]
    check(running, "the long job never ran")
    proc.terminate()
    out, err = proc.communicate(timeout=30)
    check(proc.returncode == 128 + 15, f"run after SIGTERM: exit {proc.returncode}: {err}")
    check(f"levelsetctl: cancelled: job {running[0]} cancelled" in err, err)
    for _ in range(100):
        state = ctx.http("GET", f"/api/v1/jobs/{running[0]}")[1]["state"]
        if state != "running":
            break
        time.sleep(0.1)
    check(state == "cancelled", f"the job is {state} after its client was killed")

    # A dropped event stream resumes with Last-Event-ID: every log line once, in order.
    target = int(ctx.url.rsplit(":", 1)[1])
    proxy = CuttingProxy(target, cut=900)
    jid = evolve_job(ctx, sid, 200)
    p = ctx.ok(["jobs", "wait", jid], server=f"http://127.0.0.1:{proxy.port}")
    check(proxy.cuts == 1 and "connection lost" in p.stderr, f"the stream was not cut: {p.stderr}")
    check(step_lines(p.stderr) == list(range(25, 201, 25)), f"log lines after the resume: {p.stderr}")

    # Tokens: --token and $LEVELSET_TOKEN are sent as a bearer token; none is refused.
    token = "levelsetctl-test-token-0123456789"
    secured = Daemon(ctx.levelsetd, os.path.join(ctx.scratch, "data_tokens"), ctx.env,
                     ["--tokens", token, "--max-upload-bytes", "1000000"])
    try:
        ctx.refused(["sessions", "list"], 1, "unauthorized", server=secured.url)
        ctx.ok(["--token", token, "sessions", "list"], server=secured.url)
        p = subprocess.run([ctx.ctl, "sessions", "create", "--primitive", "box", "--resolution", "16"],
                           capture_output=True, text=True, env=dict(ctx.env, LEVELSET_SERVER=secured.url,
                                                                    LEVELSET_TOKEN=token))
        check(p.returncode == 0 and "-s-" in p.stdout, f"$LEVELSET_SERVER / $LEVELSET_TOKEN: {p.stderr}")
        # An upload over max_upload_bytes: 413 from the server before it reads the body (it
        # validated an empty file as "the file is empty" before), and from levelsetctl.
        big = os.path.join(ctx.scratch, "big.off")
        open(big, "wb").write(b"OFF\n" + b" " * 3_000_000)
        # (headers only: the answer must come before any of the body is sent)
        sock = socket.create_connection(("127.0.0.1", int(secured.url.rsplit(":", 1)[1])), timeout=30)
        sock.sendall(f"POST /api/v1/uploads?format=off HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer {token}\r\n"
                     f"Content-Length: {os.path.getsize(big)}\r\n\r\n".encode())
        answer = b""
        while b"\r\n\r\n" not in answer or not answer.rstrip().endswith(b"}"):
            d = sock.recv(65536)
            if not d:
                break
            answer += d
        sock.close()
        check(answer.startswith(b"HTTP/1.1 413") and b'"payload_too_large"' in answer, f"early refusal: {answer!r}")
        ctx.refused(["--token", token, "upload", big], 1, "payload_too_large", server=secured.url)
        ctx.refused(["--token", token, "upload", big, "--format", "nope"], 1, "unsupported_format", server=secured.url)
    finally:
        secured.stop()

    # Uploads: a good one, and malformed ones refused with the server's own message.
    mesh = os.path.join(cgal, "meshes", "elephant.off")
    uid = ctx.ok(["upload", mesh]).stdout.strip()
    check(re.fullmatch(r"[a-z0-9-]+-u-[0-9a-f]{16}\.off", uid) is not None, f"upload id {uid!r}")
    status, meta = ctx.http("GET", f"/api/v1/uploads/{uid}")
    check(status == 200 and meta["bytes"] == os.path.getsize(mesh), f"upload {meta}")
    bad = os.path.join(ctx.scratch, "truncated.off")
    open(bad, "w").write("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    msg = ctx.refused(["upload", bad], 1, "truncated")
    status, body = ctx.http("POST", "/api/v1/uploads?format=off", open(bad, "rb").read())
    expected = re.sub(r"-u-[0-9a-f]{16}", "-u-X", body["error"]["message"])
    check(status == 400 and re.sub(r"-u-[0-9a-f]{16}", "-u-X", msg) == expected, f"{msg!r} vs {body}")
    check(".part-" not in msg, f"the message names a temporary file: {msg}")
    bad_ply = os.path.join(ctx.scratch, "bad.ply")
    open(bad_ply, "wb").write(b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n2\n")
    status, body = ctx.http("POST", "/api/v1/uploads?format=ply", open(bad_ply, "rb").read())
    check(status >= 400, f"the server accepted a malformed ply: {body}")
    msg = ctx.refused(["upload", bad_ply], 1, body["error"]["code"])
    check(re.sub(r"-u-[0-9a-f]{16}", "-u-X", msg) == re.sub(r"-u-[0-9a-f]{16}", "-u-X", body["error"]["message"]), msg)
    ctx.refused(["upload", bad, "--format", "nope"], 1, "unsupported_format")
    ctx.refused(["upload", os.path.join(ctx.scratch, "a.vtk")], 2, "unknown_format")
    # A session from the upload (a job makes it): --wait prints the session.
    ctx.refused(["sessions", "create", "--primitive", "box", "--param", "a=1"], 2, "usage")
    sid2 = ctx.ok(["sessions", "create", "--upload", uid, "--param", "raster.resolution=32", "--wait"]).stdout.strip()
    check(re.fullmatch(r"[a-z0-9-]+-s-[0-9a-f]{16}", sid2) is not None, f"session from an upload: {sid2!r}")
    ctx.ok(["sessions", "delete", sid2])
    ctx.refused(["sessions", "show", sid2], 1, "not_found")


def main():
    if len(sys.argv) != 7:
        sys.exit(__doc__)
    levelsetd, ctl, scratch, cgal, jobs_dir = (os.path.abspath(a) for a in sys.argv[1:6])
    scenario = sys.argv[6]
    for path in (levelsetd, ctl):
        check(os.access(path, os.X_OK), f"missing binary {path}")
    check(os.path.isdir(os.path.join(cgal, "meshes")), f"missing CGAL data at {cgal}")
    scratch = os.path.join(scratch, scenario)
    shutil.rmtree(scratch, ignore_errors=True)
    os.makedirs(scratch)
    env = dict(os.environ, LEVELSET_CGAL_DATA=cgal)
    env.pop("LEVELSET_SERVER", None)
    env.pop("LEVELSET_TOKEN", None)
    t0 = time.time()
    daemon = None
    try:
        # Two jobs at once: each runs in a TBB arena of half the cores (one thread on two cores),
        # so "jobs" also shows the outputs do not depend on the thread count.
        daemon = Daemon(levelsetd, os.path.join(scratch, "data"), env, ["--max-jobs", "2"])
        ctx = Ctx(levelsetd, ctl, scratch, env, daemon.url)
        if scenario == "jobs":
            scenario_jobs(ctx, cgal, jobs_dir)
        elif scenario == "commands":
            scenario_commands(ctx, cgal, os.path.join(os.path.dirname(os.path.dirname(jobs_dir)), "README.md"),
                              jobs_dir)
        else:
            fail(f"unknown scenario {scenario}")
    except Failure as e:
        if daemon is not None and os.path.exists(daemon.stderr):
            tail = open(daemon.stderr, errors="replace").read()[-3000:]
            print(f"--- the daemon's stderr (last 3000 characters):\n{tail}", file=sys.stderr)
        sys.exit(f"levelsetctl_cli: {scenario}: FAIL after {time.time() - t0:.1f} s: {e}")
    finally:
        if daemon is not None:
            daemon.stop()
    print(f"levelsetctl_cli: {scenario}: passed in {time.time() - t0:.1f} s")


if __name__ == "__main__":
    main()
