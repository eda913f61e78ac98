#!/usr/bin/python3
"""The deployment files say what the daemon needs (issue 18): compose and Kubernetes manifests
parse as YAML with the expected kinds, probes, ports, volumes and grace periods; the container's
final stage installs install-deps.sh's runtime group and nothing else (one source of truth);
the systemd unit passes `systemd-analyze verify`.

Usage: deploy_files.py SOURCE_DIR LEVELSETD
"""
import os
import re
import subprocess
import sys
import tempfile

import yaml

SRC, BIN = sys.argv[1], sys.argv[2]
DEPLOY = os.path.join(SRC, "deploy")
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("deploy_files: FAILED:", what, file=sys.stderr)


def size_bytes(text):
    m = re.fullmatch(r"(\d+(?:\.\d+)?)\s*([KMGT]?)i?B?", str(text))
    return float(m.group(1)) * 1024 ** "_KMGT".index(m.group(2) or "_") if m else None


# ---- compose
compose = yaml.safe_load(open(os.path.join(DEPLOY, "compose.yaml")))
svc = compose["services"]["levelsetd"]
check(svc["build"]["dockerfile"] == "deploy/Dockerfile", "compose builds deploy/Dockerfile")
check("127.0.0.1:8080:8080" in svc["ports"], "compose publishes the port on loopback")
check(any(v.startswith("levelset-data:/var/lib/levelset") for v in svc["volumes"]) and "levelset-data" in compose["volumes"],
      "compose keeps the data on a named volume")
check("levelset-tokens" in svc["secrets"] and svc["environment"]["LEVELSET_TOKEN_FILE"].endswith("levelset-tokens"),
      "compose passes the token secret")
grace = int(str(svc["stop_grace_period"]).rstrip("s"))
check(grace > int(svc["environment"]["LEVELSET_SHUTDOWN_DEADLINE"]), "compose's grace period exceeds the shutdown deadline")

# ---- Kubernetes
docs = [d for d in yaml.safe_load_all(open(os.path.join(DEPLOY, "k8s", "levelsetd.yaml"))) if d]
kinds = sorted(d["kind"] for d in docs)
check(kinds == ["Secret", "Service", "Service", "StatefulSet"], f"k8s kinds: {kinds}")
sts = next(d for d in docs if d["kind"] == "StatefulSet")
services = [d for d in docs if d["kind"] == "Service"]
check(any(s["spec"].get("clusterIP") == "None" and s["metadata"]["name"] == sts["spec"]["serviceName"] for s in services),
      "a headless Service names the StatefulSet's pods")
pod = sts["spec"]["template"]["spec"]
c = pod["containers"][0]
env = {e["name"]: e for e in c["env"]}
check(c["livenessProbe"]["httpGet"]["path"] == "/healthz" and c["readinessProbe"]["httpGet"]["path"] == "/readyz",
      "probes on /healthz and /readyz")
check(c["ports"][0]["containerPort"] == 8080, "container port 8080")
check(env["LEVELSET_REPLICA"]["valueFrom"]["fieldRef"]["fieldPath"] == "metadata.name", "replica name from the pod name")
check(pod["terminationGracePeriodSeconds"] > int(env["LEVELSET_SHUTDOWN_DEADLINE"]["value"]),
      "the grace period exceeds the shutdown deadline")
claims = sts["spec"]["volumeClaimTemplates"]
check(len(claims) == 1 and any(m["name"] == claims[0]["metadata"]["name"] and m["mountPath"] == "/var/lib/levelset"
                               for m in c["volumeMounts"]), "one claim per replica, mounted as the data directory")
limit = size_bytes(c["resources"]["limits"]["memory"])
check(limit is not None and limit > size_bytes(env["LEVELSET_MAX_BAND_MEMORY"]["value"]),
      "the memory limit leaves room above the band budget")
check(pod["securityContext"]["runAsNonRoot"] is True, "non-root")
peers = dict(item.split("=", 1) for item in env["LEVELSET_PEERS"]["value"].split(","))
check(sorted(peers) == [f"{sts['metadata']['name']}-{i}" for i in range(sts["spec"]["replicas"])] and
      all(f".{sts['spec']['serviceName']}:" in url for url in peers.values()),
      f"the peer list names every replica through the headless Service: {peers}")

# ---- Dockerfile: the final stage's packages are install-deps.sh's runtime group, nothing else
docker = open(os.path.join(DEPLOY, "Dockerfile")).read()
stages = re.split(r"^FROM ", docker, flags=re.M)
final = stages[-1]
check("install-deps.sh runtime" in final and "apt-get install" not in final, "final stage: the runtime group only")
check(re.search(r"^USER (?!root)\w+", final, re.M) is not None, "the image runs as a non-root user")
check("HEALTHCHECK" in final and "/healthz" in final, "HEALTHCHECK on /healthz")
check(re.search(r"^VOLUME /var/lib/levelset", final, re.M) is not None, "the data directory is a volume")
runtime = subprocess.run(["bash", os.path.join(DEPLOY, "install-deps.sh"), "list-runtime"], capture_output=True, text=True,
                         check=True).stdout.split()
check(len(runtime) >= 10 and "libosmesa6" in runtime and "libcpp-httplib0.11" in runtime,
      f"the runtime group lists what levelsetd loads: {runtime}")
# Every library levelsetd links directly (its NEEDED entries) comes from a package of the
# runtime group (or libc's); apt brings what those packages depend on.
ldd = subprocess.run(["ldd", BIN], capture_output=True, text=True).stdout
where = dict(re.findall(r"^\s*(\S+) => (/\S+)", ldd, re.M))
needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+?)\]", subprocess.run(["readelf", "-d", BIN],
                                                                              capture_output=True, text=True).stdout)
check(len(needed) >= 8, f"readelf found the NEEDED libraries: {needed}")
for lib in (where.get(name, name) for name in needed):
    # With merged /usr, dpkg may list the file under /lib or under /usr/lib.
    owner = ""
    for candidate in (lib, "/usr" + lib if not lib.startswith("/usr") else lib[4:], os.path.realpath(lib)):
        out = subprocess.run(["dpkg", "-S", candidate], capture_output=True, text=True).stdout
        if out:
            owner = out.split(":")[0]
            break
    check(owner in runtime or owner in ("libc6", "libstdc++6", "libgcc-s1", "libcrypt1") or owner.startswith("libssl") or
          owner.startswith("libbrotli") or owner.startswith("libgcc"), f"{lib} comes from {owner or '?'}, not in the runtime group")

# ---- systemd unit (ExecStart pointed at the built binary so that verify can see it)
with tempfile.TemporaryDirectory() as tmp:
    unit = os.path.join(tmp, "levelsetd.service")
    text = open(os.path.join(DEPLOY, "levelsetd.service")).read().replace("/usr/local/bin/levelsetd", os.path.abspath(BIN))
    open(unit, "w").write(text)
    r = subprocess.run(["systemd-analyze", "verify", unit], capture_output=True, text=True)
    check(r.returncode == 0, f"systemd-analyze verify: {r.returncode} {r.stderr.strip()}")

if failures:
    sys.exit(1)
print("deploy_files: compose, Kubernetes, Dockerfile and systemd unit check out")
