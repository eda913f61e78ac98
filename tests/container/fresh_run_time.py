#!/usr/bin/python3
"""`make run` on a fresh machine, timed (issue 18; make fresh-run-time, not part of CI).

The debootstrap bookworm base (as make container-test builds it) runs as a container with the
repository's files copied in (tracked and untracked-not-ignored: no build/ from this machine).
Inside it: apt-get install make (a fresh Debian has none), then `make run` as the README says
(install-deps.sh build + runtime from the mirror, levelsetd alone built, the main job run).
Prints the times, with make run split at its output (packages / build / job). Stops its dockerd
and removes everything, also on failure.

Usage: fresh_run_time.py        (as root)
"""
import os
import re
import subprocess
import sys
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, HERE)
from docker_env import BASE_TAG, ROOT, Dockerd, Failure, base_image, log  # noqa: E402

NAME = f"levelset-fresh-{os.getpid()}"


def repo_tar():
    """The working tree's files (as git sees them, ignored ones left out) as a tar under src/."""
    files = subprocess.run(["git", "-C", ROOT, "ls-files", "-z", "-co", "--exclude-standard"], capture_output=True,
                           check=True).stdout.split(b"\0")
    files = [f for f in files if f and os.path.isfile(os.path.join(ROOT, f.decode()))]
    return subprocess.run(["tar", "-C", ROOT, "--null", "-T", "-", "--transform", "s,^,src/,", "-cf", "-"],
                          input=b"\0".join(files), capture_output=True, check=True).stdout


def timed_exec(dockerd, script):
    """Runs bash -c SCRIPT in the container; returns (rc, seconds, [(seconds since start, line)])."""
    t0 = time.monotonic()
    p = subprocess.Popen([dockerd.client, "-H", dockerd.host, "exec", "-w", "/src", NAME, "bash", "-c", script],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    lines = []
    for raw in p.stdout:
        line = raw.decode("utf-8", "replace").rstrip()
        lines.append((time.monotonic() - t0, line))
        print(f"  | {line}", flush=True)
    rc = p.wait()
    return rc, time.monotonic() - t0, lines


def main():
    dockerd, failed, rows = None, None, []
    try:
        dockerd = Dockerd()
        base, made, imported = base_image(dockerd)
        rows.append(("base image (debootstrap, import)", made + imported))
        dockerd.run("run", "-d", "--name", NAME, base, "sleep", "infinity", capture=True)
        dockerd.run("cp", "-", f"{NAME}:/", input=repo_tar(), capture=True)
        rc, seconds, _ = timed_exec(dockerd, "apt-get update -qq && apt-get install -y -qq --no-install-recommends make "
                                             ">/dev/null")
        if rc != 0:
            raise Failure(f"apt-get install make: exit {rc}")
        rows.append(("apt-get install make", seconds))
        rc, seconds, lines = timed_exec(dockerd, "make run")
        if rc != 0:
            raise Failure(f"make run on the fresh machine: exit {rc}")
        out = dockerd.run("exec", NAME, "bash", "-c", "ls /src/out", capture=True).stdout.decode().split()
        if not out:
            raise Failure("make run wrote nothing to out/")
        build = [t for t, line in lines if re.match(r"\[\d+/\d+\]", line)]
        if build:
            rows.append(("  make run: packages (install-deps build runtime)", build[0]))
            rows.append(("  make run: configure + build levelsetd", build[-1] - build[0]))
            rows.append(("  make run: the main job", seconds - build[-1]))
        rows.append(("make run (fresh machine)", seconds))
        log(f"make run wrote out/: {' '.join(out)}")
    except Failure as e:
        failed = str(e)
    except Exception:
        failed = traceback.format_exc()
    finally:
        if dockerd is not None:
            dockerd.run("rm", "-f", NAME, check=False, capture=True)
            dockerd.run("rmi", "-f", BASE_TAG, check=False, capture=True)
            dockerd.stop()
    log("---- fresh machine")
    for name, seconds in rows:
        print(f"  {name:<50} {seconds:8.1f} s", flush=True)
    if failed:
        print(f"fresh-run-time: FAILED: {failed}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
