"""Docker on this machine for the container scripts (see ../../../shared/notes/stack.md, "Containers").

Dockerd(): dockerd on its own socket, data root and exec root under a fresh temp dir (the Debian
package's service does not start here); stop() ends it by its PID and removes that dir.
docker(...) runs the docker.io client against it. base_image() imports a Debian bookworm minbase
made by debootstrap from the apt mirror this machine uses (no registry is reachable); the rootfs
tarball is cached under build/container/ between runs.
"""
import glob
import hashlib
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CACHE = os.path.join(ROOT, "build", "container")
BASE_TAG = "localhost/levelset-bookworm-base:test"


class Failure(Exception):
    """A check or a step failed; the message says which."""


def need(tool):
    path = shutil.which(tool) or (f"/usr/sbin/{tool}" if os.path.exists(f"/usr/sbin/{tool}") else None)
    if path is None:
        raise Failure(f"{tool} not found: run `bash deploy/install-deps.sh container` (make container-test does)")
    return path


def log(msg):
    print(f"[container] {msg}", flush=True)


class Dockerd:
    def __init__(self, start_timeout=60):
        if os.geteuid() != 0:
            raise Failure("dockerd needs root")
        self.dockerd = need("dockerd")
        # The docker.io package's client (matches its dockerd), not another docker on PATH.
        self.client = "/usr/bin/docker" if os.path.exists("/usr/bin/docker") else need("docker")
        # Short path: the socket's name must fit a sockaddr_un.
        self.dir = tempfile.mkdtemp(prefix="lsdk-", dir="/tmp")
        self.host = f"unix://{self.dir}/docker.sock"
        self.log_path = os.path.join(self.dir, "dockerd.log")
        self._log = open(self.log_path, "wb")
        self.proc = subprocess.Popen([self.dockerd, "--data-root", f"{self.dir}/data", "--exec-root", f"{self.dir}/exec",
                                     "--pidfile", f"{self.dir}/dockerd.pid", "-H", self.host],
                                    stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + start_timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise Failure(f"dockerd exited with {self.proc.returncode}: {self.read_log()[-2000:]}")
            if os.path.exists(f"{self.dir}/docker.sock") and self.run("version", check=False, capture=True).returncode == 0:
                return
            time.sleep(0.2)
        self.stop()
        raise Failure(f"dockerd not answering within {start_timeout} s: {self.read_log()[-2000:]}")

    def read_log(self):
        with open(self.log_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def run(self, *args, check=True, capture=False, input=None, timeout=None):
        r = subprocess.run([self.client, "-H", self.host, *args], input=input, timeout=timeout,
                           stdout=subprocess.PIPE if capture else None, stderr=subprocess.PIPE if capture else None)
        if check and r.returncode != 0:
            err = r.stderr.decode("utf-8", "replace")[-2000:] if capture else "(see above)"
            raise Failure(f"docker {' '.join(args[:3])} ... exited {r.returncode}: {err}")
        return r

    def out(self, *args, **kw):
        return self.run(*args, capture=True, **kw).stdout.decode().strip()

    def stop(self, timeout=60):
        """SIGTERM to our dockerd (by its PID), then its directory goes (data root included)."""
        if self.proc.poll() is None:
            os.kill(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.kill(self.proc.pid, signal.SIGKILL)
                self.proc.wait(timeout=30)
        self._log.close()
        # Mounts dockerd left behind (overlays, netns) under our directory, deepest first.
        with open("/proc/mounts") as f:
            mounts = [line.split()[1] for line in f if line.split()[1].startswith(self.dir + "/")]
        for m in sorted(mounts, key=len, reverse=True):
            subprocess.run(["umount", "-l", m], stderr=subprocess.DEVNULL)
        shutil.rmtree(self.dir, ignore_errors=True)
        if os.path.exists(self.dir):
            raise Failure(f"could not remove dockerd's directory {self.dir}")


def apt_sources():
    """[(uri, suite, components)] of the bookworm Debian entries in /etc/apt/sources.list*."""
    entries = []
    files = ["/etc/apt/sources.list"] + sorted(glob.glob("/etc/apt/sources.list.d/*.list")) + \
        sorted(glob.glob("/etc/apt/sources.list.d/*.sources"))
    for path in files:
        if not os.path.exists(path):
            continue
        text = open(path).read()
        if path.endswith(".sources"):
            for stanza in re.split(r"\n\s*\n", text):
                fields = {}
                for line in stanza.splitlines():
                    if line.startswith("#") or ":" not in line:
                        continue
                    key, _, value = line.partition(":")
                    fields[key.strip().lower()] = value.split()
                if "deb" not in fields.get("types", []) or fields.get("enabled", ["yes"])[0] == "no":
                    continue
                for uri in fields.get("uris", []):
                    for suite in fields.get("suites", []):
                        entries.append((uri, suite, fields.get("components", ["main"])))
        else:
            for line in text.splitlines():
                m = re.match(r"\s*deb\s+(?:\[[^\]]*\]\s+)?(\S+)\s+(\S+)\s+(.+)", line)
                if m:
                    entries.append((m.group(1), m.group(2), m.group(3).split()))
    return [e for e in entries if e[1].startswith("bookworm")]


def base_rootfs_tar():
    """A debootstrap minbase tarball of bookworm from this machine's mirror (cached). Returns
    (path, seconds spent making it, 0 when cached)."""
    sources = apt_sources()
    mirror = next((uri for uri, suite, _ in sources if suite == "bookworm"), None)
    if mirror is None:
        raise Failure("no 'bookworm' entry in /etc/apt/sources.list*: no mirror for debootstrap")
    lines = "".join(f"deb {uri} {suite} {' '.join(comps)}\n" for uri, suite, comps in sources)
    key = hashlib.sha256(lines.encode()).hexdigest()[:12]
    tar = os.path.join(CACHE, f"bookworm-minbase-{key}.tar")
    if os.path.exists(tar):
        return tar, 0.0
    debootstrap = need("debootstrap")
    os.makedirs(CACHE, exist_ok=True)
    t0 = time.monotonic()
    rootfs = tempfile.mkdtemp(prefix="rootfs-", dir=CACHE)
    try:
        r = subprocess.run([debootstrap, "--variant=minbase", "bookworm", rootfs, mirror], capture_output=True, text=True)
        if r.returncode != 0:
            raise Failure(f"debootstrap from {mirror} failed ({r.returncode}): {(r.stdout + r.stderr)[-2000:]}")
        # The image's apt sees what this machine's apt sees (updates and security included).
        with open(os.path.join(rootfs, "etc", "apt", "sources.list"), "w") as f:
            f.write(lines)
        subprocess.run(["tar", "--numeric-owner", "-C", rootfs, "-cf", tar + ".part", "."], check=True)
        os.replace(tar + ".part", tar)
    finally:
        shutil.rmtree(rootfs, ignore_errors=True)
    return tar, time.monotonic() - t0


def base_image(dockerd, tag=BASE_TAG):
    """Imports the minbase tarball as TAG; returns (tag, debootstrap seconds, import seconds)."""
    tar, made = base_rootfs_tar()
    t0 = time.monotonic()
    with open(tar, "rb") as f:
        r = subprocess.run([dockerd.client, "-H", dockerd.host, "import", "--change", 'CMD ["/bin/bash"]', "-", tag],
                           stdin=f, capture_output=True)
    if r.returncode != 0:
        raise Failure(f"docker import failed: {r.stderr.decode()[-2000:]}")
    return tag, made, time.monotonic() - t0

