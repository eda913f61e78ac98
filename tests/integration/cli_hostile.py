#!/usr/bin/python3
"""Hostile input against the real levelsetd (issue 14), one regression per reported item.

1. No command ever replaces a non-regular file, follows or replaces a symbolic link, or writes
   over one of its inputs: every subcommand is run once normally (so its arguments are known
   to be right) and then with each hostile destination for -o and --stats; each must be refused
   before any work, with the destination left exactly as it was.
2. Outputs are checked before the computation (a bad output name costs no time, leaves nothing).
3. Bombs: a PLY header of 100k elements or properties, measured in a child for time and peak
   memory (getrusage of the children).
4. Wrong results: measure far from the origin, measure --iso beyond the band, info on a PLY
   with a bad face or an out-of-range uchar.
5. Messages: short numbers, NaN named, integers in exponent form accepted.

Usage: cli_hostile.py LEVELSETD SCRATCH_DIR
"""
import json
import math
import os
import resource
import shutil
import stat
import subprocess
import sys
import time

BIN, DIR = sys.argv[1], sys.argv[2]
failures = []
checks = 0


def check(ok, what):
    global checks
    checks += 1
    if not ok:
        failures.append(what)
        print("cli_hostile: FAILED:", what, file=sys.stderr)


def run(*args, timeout=120):
    r = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True, timeout=timeout)
    return r.returncode, r.stdout, r.stderr


def path(name):
    return os.path.join(DIR, name)


def snapshot(p):
    """What a destination is: kind, link target, content hash (regular files)."""
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        return ("absent",)
    if stat.S_ISLNK(st.st_mode):
        return ("link", os.readlink(p))
    if stat.S_ISREG(st.st_mode):
        with open(p, "rb") as f:
            return ("file", hash(f.read()))
    return ("special", stat.S_IFMT(st.st_mode), st.st_ino)


def expect_refused(args, destination, what, pattern=None):
    before = snapshot(destination)
    rc, out, err = run(*args)
    check(0 < rc < 128, f"{what}: exit {rc} (expected a refusal): {err.strip()}")
    check(err.startswith("levelsetd: ") and len(err.strip().splitlines()) == 1, f"{what}: stderr {err!r}")
    if pattern:
        check(pattern in err, f"{what}: stderr lacks '{pattern}': {err.strip()}")
    check(snapshot(destination) == before, f"{what}: {destination} changed")
    leftovers = [f for f in os.listdir(DIR) if ".tmp-" in f]
    check(not leftovers, f"{what}: temp files left: {leftovers}")


# --- inputs ---------------------------------------------------------------------------------
shutil.rmtree(DIR, ignore_errors=True)
os.makedirs(DIR)
rc, _, err = run("primitive", "sphere", "-r", 24, "-b", 3, "-o", path("a.lsg"))
assert rc == 0, err
rc, _, err = run("primitive", "torus", "-r", 24, "-b", 3, "-o", path("b.lsg"))
assert rc == 0, err
with open(path("box.off"), "w") as f:
    f.write("OFF\n8 6 0\n")
    for x in (0, 1):
        for y in (0, 1):
            for z in (0, 1):
                f.write(f"{x} {y} {z}\n")
    for q in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
        f.write("4 %d %d %d %d\n" % q)
with open(path("pts.xyz"), "w") as f:
    n = 400
    for i in range(n):  # a Fibonacci sphere
        z = 1 - 2 * (i + 0.5) / n
        r = math.sqrt(1 - z * z)
        a = i * math.pi * (3 - math.sqrt(5))
        f.write(f"{r * math.cos(a)} {r * math.sin(a)} {z}\n")
# A 16^3 uint8 INR with a bright cube in the middle.
header = "#INRIMAGE-4#{\nXDIM=16\nYDIM=16\nZDIM=16\nVDIM=1\nTYPE=unsigned fixed\nPIXSIZE=8 bits\nCPU=decm\nVX=1\nVY=1\nVZ=1\n"
header += "\n" * (256 - len(header) - 4) + "##}\n"
voxels = bytearray(16 ** 3)
for z in range(4, 12):
    for y in range(4, 12):
        for x in range(4, 12):
            voxels[(z * 16 + y) * 16 + x] = 200
with open(path("img.inr"), "wb") as f:
    f.write(header.encode() + bytes(voxels))
with open(path("job.conf"), "w") as f:
    f.write("job = offset\ninput { lsg = a.lsg }\noffset { distance = 0.02 }\n")

# Each subcommand: (name, args before the output, output extension, its input file or None).
commands = [
    ("primitive", ["primitive", "sphere", "-r", 16], ".lsg", None),
    ("cpt", ["cpt", path("box.off"), "-r", 16], ".lsg", path("box.off")),
    ("redistance", ["redistance", path("a.lsg")], ".lsg", path("a.lsg")),
    ("mesh", ["mesh", path("a.lsg")], ".ply", path("a.lsg")),
    ("evolve", ["evolve", path("a.lsg"), "--speed", "1", "--steps", 1], ".lsg", path("a.lsg")),
    ("offset", ["offset", path("a.lsg"), "--distance", 0.02], ".lsg", path("a.lsg")),
    ("fair", ["fair", path("a.lsg"), "--steps", 1], ".lsg", path("a.lsg")),
    ("minmax", ["minmax", path("a.lsg"), "--radius", 1, "--max-steps", 1], ".lsg", path("a.lsg")),
    ("csg", ["csg", "union", path("a.lsg"), path("b.lsg")], ".lsg", path("b.lsg")),
    ("reconstruct", ["reconstruct", path("pts.xyz"), "--resolution", 24], ".ply", path("pts.xyz")),
    ("segment", ["segment", path("img.inr"), "--seed", "8,8,8", "--steps", 2], ".lsg", path("img.inr")),
    ("voronoi", ["voronoi", "--seed", "0,0,0", "--seed", "1,1,1", "--bounds", "0,0,0,1,1,1", "-r", 8], ".nrrd", None),
    ("path", ["path", "--from", "0,0,0", "--to", "1,1,1", "--bounds", "0,0,0,1,1,1", "-r", 8], ".txt", None),
    ("sample", ["sample", path("a.lsg"), "--points", path("pts.xyz")], ".txt", path("a.lsg")),
]

os.mkfifo(path("fifo.lsg"))
for name, args, ext, the_input in commands:
    good = path(f"good_{name}{ext}")
    rc, _, err = run(*args, "-o", good)
    check(rc == 0 and os.path.isfile(good), f"{name}: the normal run failed: {err.strip()}")
    fifo = path(f"fifo_{name}{ext}")
    os.mkfifo(fifo)
    dangling = path(f"dangling_{name}{ext}")
    os.symlink(path(f"elsewhere_{name}{ext}"), dangling)
    to_file = path(f"link_{name}{ext}")
    os.symlink(good, to_file)
    expect_refused([*args, "-o", fifo], fifo, f"{name} -o FIFO", "not a regular file")
    expect_refused([*args, "-o", dangling], dangling, f"{name} -o dangling link", "symbolic link")
    check(not os.path.exists(path(f"elsewhere_{name}{ext}")), f"{name}: followed a dangling link")
    expect_refused([*args, "-o", to_file], good, f"{name} -o link to a file", "symbolic link")
    has_stats = name != "sample"  # sample prints values; it has no --stats
    if has_stats:
        expect_refused([*args, "-o", path(f"x_{name}{ext}"), "--stats", fifo], fifo, f"{name} --stats FIFO")
        expect_refused([*args, "-o", path(f"y_{name}{ext}"), "--stats", path(f"y_{name}{ext}")],
                       path(f"y_{name}{ext}"), f"{name} two outputs to one file", "two outputs")
    if the_input:
        if os.path.splitext(the_input)[1] == ext:
            expect_refused([*args, "-o", the_input], the_input, f"{name} -o its input", "also an input")
        if has_stats:
            expect_refused([*args, "-o", path(f"z_{name}{ext}"), "--stats", the_input], the_input,
                           f"{name} --stats its input", "also an input")
    # The wrong extension for the option's format, refused before any work.
    wrong = ".ply" if ext != ".ply" else ".lsg"
    if ext != ".txt":
        expect_refused([*args, "-o", path(f"w_{name}{wrong}")], path(f"w_{name}{wrong}"),
                       f"{name} -o with a {wrong} name", "expected a file name for")

# Devices: as root, /dev/null and /dev/full stay character devices.
for dev in ("/dev/null", "/dev/full"):
    expect_refused(["primitive", "knot", "--resolution", 32, "--band", 3, "-o", dev], dev, f"-o {dev}",
                   "not a regular file")
    check(stat.S_ISCHR(os.stat(dev).st_mode), f"{dev} is no longer a character device")
# With --allow-special-outputs a band goes to stdout (and the summary line to stderr).
r = subprocess.run([BIN, "--allow-special-outputs", "primitive", "sphere", "-r", "16", "-o", "/dev/stdout"],
                   capture_output=True)
with open(path("good_primitive.lsg"), "rb") as f:
    check(r.returncode == 0 and r.stdout == f.read(),
          f"-o /dev/stdout with --allow-special-outputs: exit {r.returncode}, {len(r.stdout)} bytes, not the band")
check(b"active voxels" in r.stderr, "the summary line did not move to stderr")
with open(path("stdout.lsg"), "wb") as f:
    f.write(r.stdout)
rc, out, err = run("info", path("stdout.lsg"))
check(rc == 0 and "narrow band" in out, f"the band written to stdout does not read back: {err.strip()}")

# Jobs: an input under the job's output name is refused before any work; so is a bad output.
shutil.copy(path("box.off"), path("bunny.off"))
with open(path("bunny.conf"), "w") as f:
    f.write("job = offset\ninput { mesh = bunny.off }\nraster { resolution = 16 }\noffset { distance = 0.02 }\n"
            "output { mesh = off }\n")
expect_refused(["run", path("bunny.conf"), "-o", DIR], path("bunny.off"), "job output over its input mesh",
               "in the output directory")
t0 = time.monotonic()
expect_refused(["run", path("job.conf"), "--set", "output.mesh=plyx", "-o", path("plyx_out")],
               path("plyx_out"), "run --set output.mesh=plyx", "plyx")
check(time.monotonic() - t0 < 2.0, "run with a bad output option computed first")
check(not os.path.exists(path("plyx_out")), "run with a bad output option left an output directory")
expect_refused(["segment", path("img.inr"), "--seed", "8,8,8", "-o", path("s.lsg"), "--mesh", path("s.inr")],
               path("s.lsg"), "segment --mesh x.inr", "expected a file name for a mesh")
expect_refused(["voronoi", "--seed", "0,0,0", "-o", path("v.lsg")], path("v.lsg"), "voronoi -o v.lsg",
               "NRRD")


# --- bombs: time and peak memory of a child -------------------------------------------------
def measured(*args):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.monotonic()
    rc, out, err = run(*args, timeout=60)
    return rc, err, time.monotonic() - t0, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, before


with open(path("elements.ply"), "w") as f:
    f.write("ply\nformat ascii 1.0\n" + "".join(f"element e{i} 0\n" for i in range(100000)) + "end_header\n")
with open(path("properties.ply"), "w") as f:
    f.write("ply\nformat ascii 1.0\nelement vertex 0\n" +
            "".join(f"property float p{i}\n" for i in range(100000)) + "end_header\n")
for bomb in ("elements.ply", "properties.ply"):
    for cmd in (["info", path(bomb)], ["cpt", path(bomb), "-r", 16, "-o", path("bomb.lsg")]):
        rc, err, seconds, peak_kb, _ = measured(*cmd)
        check(0 < rc < 128 and "limit_exceeded" in err, f"{cmd[0]} {bomb}: exit {rc}: {err.strip()[:200]}")
        check(seconds < 2.0, f"{cmd[0]} {bomb} took {seconds:.2f} s (was 20-60 s)")
        # ru_maxrss of the children is the largest child so far: bounded by what any command took.
        check(peak_kb < 200 * 1024, f"{cmd[0]} {bomb}: peak {peak_kb} KiB")

# --- wrong results --------------------------------------------------------------------------
for shift in (5e6, 1e9):
    cube = path(f"cube_{shift:g}.off")
    with open(cube, "w") as f:
        f.write("OFF\n8 6 0\n")
        for x in (0, 1):
            for y in (0, 1):
                for z in (0, 1):
                    f.write(f"{x + shift!r} {y + shift!r} {z + 100}\n")
        for q in ((0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)):
            f.write("4 %d %d %d %d\n" % q)
    rc, _, err = run("cpt", cube, "-r", 32, "-o", cube + ".lsg")
    check(rc == 0, f"cpt of the shifted cube: {err.strip()}")
    rc, out, err = run("measure", cube + ".lsg", "--json")
    volume = json.loads(out)["volume"] if rc == 0 else float("nan")
    # Marching cubes rounds the edges: a little under 1, never -0.79 or 4e12.
    check(0.98 < volume <= 1.0, f"measure of a unit cube at {shift:g}: volume {volume}")

rc, out, _ = run("info", path("a.lsg"), "--json")
h = json.loads(out)["voxel_size"]
rc, out, err = run("measure", path("a.lsg"), "--iso", 1.2 * h, "--json")
check(rc == 0 and json.loads(out)["components"] == 1, f"measure --iso 1.2 h: {err.strip()}")
expect_refused(["measure", path("a.lsg"), "--iso", 2.5 * h], path("a.lsg"), "measure --iso 2.5 h", "leaves the band")
expect_refused(["mesh", path("a.lsg"), "--iso", -2.5 * h, "-o", path("iso.ply")], path("iso.ply"),
               "mesh --iso -2.5 h", "leaves the band")

ply_head = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n")
for name, face in (("negative", "3 0 1 -2\n"), ("empty", "0\n"), ("uchar", "300 0 1 2\n")):
    with open(path(f"{name}.ply"), "w") as f:
        f.write(ply_head + face)
    rc_info, _, err_info = run("info", path(f"{name}.ply"))
    rc_cpt, _, err_cpt = run("cpt", path(f"{name}.ply"), "-r", 16, "-o", path(f"{name}.lsg"))
    check(0 < rc_info < 128 and "parse_error" in err_info, f"info {name}.ply: exit {rc_info}: {err_info.strip()}")
    check(err_info.split(":", 1)[1] == err_cpt.split(":", 1)[1],
          f"info and cpt disagree on {name}.ply: {err_info.strip()} / {err_cpt.strip()}")

# --- messages -------------------------------------------------------------------------------
rc, _, err = run("evolve", path("a.lsg"), "--speed", "1", "--steps", 0, "-o", path("m.lsg"))
check(rc != 0 and len(err) < 200 and "found 0" in err, f"--steps 0: {err.strip()}")
rc, _, err = run("evolve", path("a.lsg"), "--speed", "1", "--steps", 1, "--drift-tolerance", "nan", "-o", path("m.lsg"))
check(rc != 0 and "NaN" in err and "negative" not in err, f"--drift-tolerance nan: {err.strip()}")
rc, _, err = run("primitive", "sphere", "--resolution", "1e2", "-o", path("e.lsg"))
check(rc == 0, f"--resolution 1e2 refused: {err.strip()}")
rc, _, err = run("cpt", path("box.off"), "--voxel-size", "1e-12", "-o", path("tiny.lsg"))
check(rc != 0 and "1e-12" in err and "0.000000" not in err and len(err) < 300, f"--voxel-size 1e-12: {err.strip()}")

print(f"cli_hostile: {checks - len(failures)} of {checks} checks passed")
sys.exit(1 if failures else 0)
