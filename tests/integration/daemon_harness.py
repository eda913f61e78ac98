"""A real `levelsetd serve` on a free loopback port, and small HTTP helpers (stdlib only).

Daemon(binary, data_dir, *flags) starts the daemon with --port 0, reads the port from its
"levelsetd listening on http://HOST:PORT" line, and stop() sends SIGTERM and waits (kill()
sends SIGKILL). request() returns (status, headers, body bytes); json_request() parses JSON.
events() reads Server-Sent Events until a predicate says stop or the stream ends.
"""
import json
import os
import re
import signal
import ssl
import subprocess
import time
import urllib.error
import urllib.request


class Daemon:
    def __init__(self, binary, data_dir, *flags, env=None, preexec_fn=None, start_timeout=20, port=0):
        self.binary, self.data_dir, self.flags = binary, data_dir, list(flags)
        self.log_path = os.path.join(data_dir + ".log")
        os.makedirs(os.path.dirname(os.path.abspath(data_dir)), exist_ok=True)
        self.log = open(self.log_path, "ab")
        full_env = dict(os.environ)
        full_env.update(env or {})
        self.proc = subprocess.Popen([binary, "serve", "--port", str(port), "--data", data_dir, *self.flags],
                                     stdout=subprocess.PIPE, stderr=self.log, env=full_env, preexec_fn=preexec_fn)
        line = self._read_ready_line(start_timeout)
        m = re.match(r"levelsetd listening on (https?)://([^:]+):(\d+)", line)
        if not m:
            self.proc.kill()
            raise RuntimeError(f"daemon did not start: {line!r}; log: {self.read_log()[-2000:]}")
        self.url = f"{m.group(1)}://{m.group(2)}:{m.group(3)}"
        self.port = int(m.group(3))

    def _read_ready_line(self, timeout):
        import select
        deadline = time.monotonic() + timeout
        buf = b""
        while time.monotonic() < deadline:
            ready, _, _ = select.select([self.proc.stdout], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                break
            ch = os.read(self.proc.stdout.fileno(), 1)
            if not ch:
                break
            if ch == b"\n":
                return buf.decode("utf-8", "replace")
            buf += ch
        return buf.decode("utf-8", "replace")

    def read_log(self):
        with open(self.log_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def stop(self, timeout=20):
        """SIGTERM; returns (exit code, seconds to exit)."""
        t0 = time.monotonic()
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
        rc = self.proc.wait(timeout=timeout)
        self.log.close()
        return rc, time.monotonic() - t0

    def kill(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(timeout=20)
        self.log.close()

    # ---- HTTP
    def _ssl(self):
        """HTTPS to a test daemon: its self-signed certificate is not verified."""
        return ssl._create_unverified_context() if self.url.startswith("https") else None

    def request(self, method, path, body=None, headers=None, timeout=60):
        data = body
        hdrs = dict(headers or {})
        if isinstance(body, (dict, list)):
            data = json.dumps(body).encode()
            hdrs.setdefault("Content-Type", "application/json")
        elif isinstance(body, str):
            data = body.encode()
        req = urllib.request.Request(self.url + path, data=data, method=method, headers=hdrs)
        try:
            with urllib.request.urlopen(req, timeout=timeout, context=self._ssl()) as r:
                return r.status, dict(r.headers), r.read()
        except urllib.error.HTTPError as e:
            return e.code, dict(e.headers), e.read()

    def json_request(self, method, path, body=None, headers=None, timeout=60):
        status, hdrs, raw = self.request(method, path, body, headers, timeout)
        try:
            parsed = json.loads(raw) if raw else None
        except ValueError:
            parsed = raw
        return status, hdrs, parsed

    def get(self, path, **kw):
        return self.json_request("GET", path, **kw)

    def post(self, path, body=None, **kw):
        return self.json_request("POST", path, body, **kw)

    def events(self, path, until=None, timeout=120, headers=None):
        """Reads SSE events [(id, type, data)] until until(event) is true or the stream ends."""
        req = urllib.request.Request(self.url + path, headers=dict(headers or {}))
        out = []
        with urllib.request.urlopen(req, timeout=timeout, context=self._ssl()) as r:
            event = {}
            for raw in r:
                line = raw.decode("utf-8").rstrip("\n")
                if line.startswith(":"):
                    continue
                if not line:
                    if event:
                        e = (int(event.get("id", 0)), event.get("event", "message"), json.loads(event.get("data", "null")))
                        out.append(e)
                        event = {}
                        if until and until(e):
                            break
                    continue
                key, _, value = line.partition(": ")
                event[key] = value
        return out

    def wait_job(self, job_id, timeout=300, headers=None):
        """Follows the job's events to its end; returns the final job description."""
        self.events(f"/api/v1/jobs/{job_id}/events", until=lambda e: e[1] == "done", timeout=timeout, headers=headers)
        return self.get(f"/api/v1/jobs/{job_id}", headers=headers)[2]


def upload(daemon, path, fmt, headers=None):
    with open(path, "rb") as f:
        data = f.read()
    return daemon.json_request("POST", f"/api/v1/uploads?format={fmt}", data,
                               headers={"Content-Type": "application/octet-stream", **(headers or {})})


def write_sphere_cloud(path, count, radius=1.0):
    """A Fibonacci sphere of `count` points (evenly spread) as an .xyz file."""
    import math
    with open(path, "w") as f:
        for i in range(count):
            z = 1 - 2 * (i + 0.5) / count
            r, a = math.sqrt(1 - z * z), i * 2.399963229728653
            f.write(f"{radius * r * math.cos(a):.6f} {radius * r * math.sin(a):.6f} {radius * z:.6f}\n")
    return path


def off_topology(text):
    """(vertices, faces, watertight, genus, components) of an ASCII OFF triangle mesh."""
    tokens = text.split()
    assert tokens[0] == "OFF"
    nv, nf = int(tokens[1]), int(tokens[2])
    pos = 4 + 3 * nv
    faces = []
    for _ in range(nf):
        k = int(tokens[pos])
        faces.append(tuple(int(t) for t in tokens[pos + 1:pos + 1 + k]))
        pos += 1 + k
    edges = {}
    parent = list(range(nv))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    used = set()
    for f in faces:
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            edges[(min(a, b), max(a, b))] = edges.get((min(a, b), max(a, b)), 0) + 1
            parent[find(a)] = find(b)
            used.add(a)
    watertight = all(c == 2 for c in edges.values())
    components = len({find(v) for v in used})
    euler = len(used) - len(edges) + len(faces)
    genus = (2 * components - euler) / 2
    return len(used), len(faces), watertight, genus, components
