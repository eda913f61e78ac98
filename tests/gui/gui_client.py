#!/usr/bin/python3
"""levelset-gui under Xvfb against a real levelsetd (run under `xvfb-run -a`, 24-bit screen).

Usage: gui_client.py LEVELSET_GUI LEVELSETD SCRATCH CGAL_DATA SCENARIO

Scenarios (each drives the window with --script: the functions the buttons call and injected
ImGui mouse / keyboard input; the window's state comes back as JSON dumps):
  workflow   connect to a daemon, load CGAL's knot.off (C), compute its distance field (B), type
             a formula into the formula box and press Evolve (G) through injected input, extract
             and shade the isosurface (F, A), save the mesh (C), screenshot (K): the image shows
             the panel and a shaded, non-empty surface; the daemon's session holds the evolved
             version; above the triangle budget the view switches to the daemon's frames, which
             follow the panel's shading (PUT view); a bad formula shows the server's error with
             its column under the box. Writes SCRATCH/levelset-gui.png (the README's picture).
  sessions   create from a primitive, rename, snapshot, evolve and Stop (the state reached is
             kept), restore the snapshot, redistance (H), load a point cloud (J) and reconstruct
             a session from it, run a job file (its session is shown),
             delete: each checked on the daemon.
  roi        thesis B's ROI option and D's Point(ROI): a sphere session, then CGAL's knot loaded (C)
             and its distance field computed with ROI checked becomes the sphere's region of
             influence (the knot's session is removed, the sphere shown again); D's ROI draws
             its points (local and remote frames); a formula reading roi evolves the sphere;
             Store / Clear ROI; a session reconstructed from points (made over the API) shows
             its cloud when selected (I), fetched from the daemon.
  reconnect  a killed daemon shows the banner; the daemon restarted on the same port clears it.
  auth       a daemon with tokens: a wrong token shows the "refuses" banner, a read-only token
             gets the server's "forbidden" error when it creates a session, a read-write token
             works and is remembered.
  embedded   no --server: the window starts its own `levelsetd serve --port 0` and stops it on
             exit, by its script's quit and on SIGTERM (no process left behind); the settings
             file keeps the panel between runs; with no script, --screenshot shows the newest
             session, writes the PNG and quits.
Missing tools (PIL, the binaries, the knot) fail the test; nothing is skipped.
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

from PIL import Image  # python3-pil; missing: the test fails here

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "integration"))
from daemon_harness import Daemon, upload  # noqa: E402

GUI, LEVELSETD, SCRATCH, CGAL, SCENARIO = sys.argv[1:6]
KNOT = os.path.join(CGAL, "meshes", "knot.off")
POINTS = os.path.join(CGAL, "points_3", "sphere_1k.xyz")
JOB_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "configs", "jobs", "evolve_dumbbell.conf")
PANEL_WIDTH = 420  # client/gui/panels.hpp kPanelWidth
WIDTH, HEIGHT = 1280, 900
BACKGROUND = (0.13, 0.13, 0.2)  # render::ViewSettings' default background


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def wait_until(pred, what, timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = pred()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("timed out waiting for " + what)


def gui_env(name):
    env = dict(os.environ)
    env["XDG_CONFIG_HOME"] = os.path.join(SCRATCH, name, "config")
    env["XDG_STATE_HOME"] = os.path.join(SCRATCH, name, "state")
    return env


def start_gui(name, script_lines, *args):
    """Starts the window with a script; returns (process, directory)."""
    d = os.path.join(SCRATCH, name)
    os.makedirs(d, exist_ok=True)
    script = os.path.join(d, "script.txt")
    with open(script, "w") as f:
        f.write("\n".join(script_lines) + "\n")
    log = open(os.path.join(d, "gui.log"), "wb")
    cmd = [GUI, "--script", script, "--width", str(WIDTH), "--height", str(HEIGHT),
           "--dump-state", os.path.join(d, "final.json"), *args]
    return subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=gui_env(name), cwd=d), d


def finish_gui(proc, d, timeout=180):
    rc = proc.wait(timeout=timeout)
    with open(os.path.join(d, "gui.log"), "rb") as f:
        log = f.read().decode("utf-8", "replace")
    check(rc == 0, f"levelset-gui exited {rc}; its log ends:\n{log[-3000:]}")
    return log


def load_json(path):
    with open(path) as f:
        return json.load(f)


def image_stats(path):
    """Panel: many distinct grey levels (text on the panel). Scene: pixels off the background,
    their brightness spread (shading) and warm hue (the surface colour)."""
    img = Image.open(path).convert("RGB")
    check(img.size == (WIDTH, HEIGHT), f"{path}: size {img.size}")
    px = img.load()
    panel = [px[x, y] for x in range(0, PANEL_WIDTH, 3) for y in range(0, HEIGHT, 3)]
    bg = tuple(round(c * 255) for c in BACKGROUND)
    scene = [px[x, y] for x in range(PANEL_WIDTH, WIDTH, 3) for y in range(60, HEIGHT, 3)]
    surface = [p for p in scene if abs(p[0] - bg[0]) + abs(p[1] - bg[1]) + abs(p[2] - bg[2]) > 60 and p[0] > p[2]]
    lum = sorted(0.3 * p[0] + 0.59 * p[1] + 0.11 * p[2] for p in surface) or [0]
    return {"panel_levels": len(set(panel)), "panel_bright": sum(1 for p in panel if sum(p) > 450),
            "surface_fraction": len(surface) / len(scene),
            "lum_spread": lum[int(0.95 * (len(lum) - 1))] - lum[int(0.05 * (len(lum) - 1))]}


def scene_fraction(path, pred):
    img = Image.open(path).convert("RGB")
    px = img.load()
    scene = [px[x, y] for x in range(PANEL_WIDTH, WIDTH, 3) for y in range(60, HEIGHT, 3)]
    return sum(1 for p in scene if pred(p)) / len(scene)


def red_pixels(path, box):
    img = Image.open(path).convert("RGB")
    px = img.load()
    x0, y0, x1, y1 = (int(v) for v in box)
    return sum(1 for x in range(x0, x1) for y in range(y0, y1)
               if px[x, y][0] > 180 and px[x, y][1] < 140 and px[x, y][2] < 140)


def with_daemon(body):
    """Runs body(daemon) against a fresh daemon on a loopback port, stopped afterwards."""
    daemon = Daemon(LEVELSETD, os.path.join(SCRATCH, "data"))
    try:
        body(daemon)
    finally:
        daemon.stop()


def scenario_workflow():
    check(os.path.isfile(KNOT), "no knot.off at " + KNOT)
    with_daemon(workflow_with)


def workflow_with(daemon):
    d = os.path.join(SCRATCH, "workflow")
    saved = os.path.join(d, "knot-evolved.ply")  # the window runs in d: a relative name there
    formula, bad = "-0.5*H", "-H + sin(x) * * 2"
    script = [
        "wait_connected 30", f"set mesh_file {KNOT}", "press load_mesh", "wait_idle 60",
        "set resolution 64", "set band 3", "click 'Compute distance field'", "wait_session 120", "wait_idle 120",
        "wait_surface 60",
        # G: typed into the box through injected input, started by clicking Evolve.
        "click ##formula", "key ctrl+a", f"type '{formula}'", "set steps 10", "click Evolve", "frames 2",
        "wait_idle 120", "expect_no_errors",
        "set iso 0", "press extract", "click smooth", "wait_surface 60", "frames 70",
        "set save_file knot-evolved.ply", "press save_mesh", "wait_idle 60",
        f"screenshot {d}/surface.png", f"dump {d}/after_evolve.json",
        # Above the triangle budget the view switches to the daemon's frames; A goes through PUT view.
        "click curvature", "wait_idle 60", "frames 3", f"dump {d}/overlay.json", "click none##field",
        # The band's slice (z) and volume rendering (View tab settings).
        "set slice 3", "frames 3", f"screenshot {d}/slice.png", "set slice 0", "set volume true", "click none",
        "frames 2", f"screenshot {d}/volume.png", "set volume false",
        "set triangle_budget 1000", "click flat", "frames 2", "wait_surface 60", "frames 30",
        f"screenshot {d}/remote.png", f"dump {d}/remote.json",
        "drag 200 -50", "frames 5", "wait_idle 30", f"dump {d}/dragged.json", "set triangle_budget 2000000",
        "click ##formula", "key ctrl+a", f"type '{bad}'", "click Evolve", "wait_formula_error 30", "frames 2",
        f"screenshot {d}/formula_error.png", f"dump {d}/formula_error.json",
    ]
    t0 = time.monotonic()
    proc, d = start_gui("workflow", script, "--server", daemon.url)
    finish_gui(proc, d)
    print(f"workflow script ran in {time.monotonic() - t0:.1f} s")
    state = load_json(os.path.join(d, "after_evolve.json"))
    check(state["connected"] and not state["errors"], f"errors after evolving: {state['errors']}")
    sid = state["session"]
    check(sid and state["version"] >= 2, f"no evolved session: {state['session']} v{state['version']}")
    ops = [j["op"] for j in state["jobs"] if j["mine"] and j["state"] == "succeeded"]
    check("cpt" in ops and "evolve" in ops, f"jobs: {state['jobs']}")
    status, _, session = daemon.get(f"/api/v1/sessions/{sid}")
    check(status == 200 and session["version"] == state["version"], f"daemon's session: {session}")
    status, _, history = daemon.get(f"/api/v1/sessions/{sid}/history")
    check(formula in json.dumps(history), f"the typed formula is not in the session's history: {history}")
    check(state["view"]["mesh_version"] == state["version"] and state["view"]["triangles"] > 1000,
          f"the local view does not show the evolved surface: {state['view']}")
    status, _, mesh = daemon.request("GET", f"/api/v1/sessions/{sid}/mesh?iso=0&format=ply")
    with open(saved, "rb") as f:
        check(f.read() == mesh, "the saved mesh differs from the daemon's")
    stats = image_stats(os.path.join(d, "surface.png"))
    print("surface.png", stats)
    check(stats["panel_levels"] >= 8 and stats["panel_bright"] > 200, f"no panel drawn: {stats}")
    check(stats["surface_fraction"] > 0.05, f"no surface in the scene: {stats}")
    check(stats["lum_spread"] > 40, f"the surface is not shaded: {stats}")
    # The README's picture (docs/levelset-gui.png is a copy): 64 colours keep it small.
    Image.open(os.path.join(d, "surface.png")).convert("RGB").quantize(colors=64).save(
        os.path.join(SCRATCH, "levelset-gui.png"), optimize=True)
    overlay = load_json(os.path.join(d, "overlay.json"))
    check(overlay["view"]["band_loaded"] and overlay["panel"]["field"] == 3 and not overlay["errors"],
          f"D's curvature: {overlay['view']} {overlay['errors']}")
    blue = scene_fraction(os.path.join(d, "slice.png"), lambda p: p[2] > 150 and p[0] < 120)
    check(blue > 0.05, f"no slice coloured by distance ({blue:.3f} of the scene)")
    lit = scene_fraction(os.path.join(d, "volume.png"), lambda p: sum(p) > 300)
    check(lit > 0.05, f"no volume rendering without the surface ({lit:.3f} of the scene)")
    print(f"slice {blue:.3f}, volume {lit:.3f} of the scene")
    evolve_jobs = [j for j in state["jobs"] if j["op"] == "evolve"]
    check(evolve_jobs and evolve_jobs[0]["fraction"] == 1.0, f"the evolve job's progress: {evolve_jobs}")
    remote = load_json(os.path.join(d, "remote.json"))
    check(remote["view"]["remote"] and remote["view"]["frames_received"] > 0, f"no remote frames: {remote['view']}")
    status, _, view = daemon.get(f"/api/v1/sessions/{sid}/view")
    check(status == 200 and view["shading"] == "flat", f"the panel's shading did not reach the daemon: {view}")
    dragged = load_json(os.path.join(d, "dragged.json"))["camera"]
    check(abs(dragged["yaw"] - 30) > 40 and abs(dragged["pitch"] - 20) > 10, f"the drag did not orbit: {dragged}")
    check(abs(view["camera"]["yaw"] - dragged["yaw"]) < 1e-6 and abs(view["camera"]["pitch"] - dragged["pitch"]) < 1e-6,
          f"the daemon's camera {view['camera']} is not the window's {dragged}")
    stats = image_stats(os.path.join(d, "remote.png"))
    print("remote.png", stats)
    check(stats["surface_fraction"] > 0.05 and stats["lum_spread"] > 20, f"no surface in the remote frame: {stats}")
    err = load_json(os.path.join(d, "formula_error.json"))
    fe = err["formula_error"]
    check(fe["formula"] == bad and fe["column"] == bad.index("* *") + 3, f"formula error: {fe}")
    check(any("expected a value" in e for e in err["errors"]), f"error text: {err['errors']}")
    box = err["widgets"]["##formula"]
    # The caret and message in red just under the box, the caret at the column's x.
    char_w = (box[2] - box[0]) / max(1, (box[2] - box[0]) // 7)
    caret_x = box[0] + 4 + (fe["column"] - 1) * 7
    under = (caret_x - 2, box[3], caret_x + 9, box[3] + 16)
    check(red_pixels(os.path.join(d, "formula_error.png"), under) > 3, f"no caret under column {fe['column']}")
    check(red_pixels(os.path.join(d, "formula_error.png"), (box[0], box[3] + 14, box[2], box[3] + 34)) > 30,
          "no error message under the formula box")
    del char_w


def scenario_sessions():
    with_daemon(sessions_with)


def sessions_with(daemon):
    d = os.path.join(SCRATCH, "sessions")
    script = [
        "wait_connected 30", "set primitive sphere", "set resolution 32", "press create_primitive", "wait_session 60",
        "wait_surface 60", "set new_name ball", "press rename", "set snapshot_name before", "press snapshot",
        "wait_idle 30", f"dump {d}/snapshot.json",
        # G's Stop: a long evolution ends at a step boundary with the state reached.
        # An outward speed (the sphere must not vanish before Stop); while it runs the local view
        # follows its latest steps (the mesh route's preview); Stop keeps the state reached.
        "set formula 0.5", "set steps 100000", "press evolve", "wait_running 60", "frames 90",
        f"dump {d}/running.json", "click Stop",
        "wait_idle 120", "wait_surface 60", f"dump {d}/stopped.json",
        "press restore", "wait_idle 30", "wait_surface 60", f"dump {d}/restored.json",
        "press redistance", "wait_idle 120", "wait_surface 60", f"dump {d}/redistanced.json",
        # J and I: a point cloud shown with the session, then a session reconstructed from it.
        f"set points_file {POINTS}", "press load_points", "set cloud 1", "wait_idle 60", f"dump {d}/points.json",
        "press reconstruct", "wait_idle 180", "wait_surface 60", f"dump {d}/reconstructed.json",
        f"set job_file {JOB_FILE}", "set_job_overrides", "press run_job_file", "wait_idle 180", "wait_surface 60",
        f"dump {d}/job_file.json", "press delete", "wait_idle 30", "frames 5", f"dump {d}/deleted.json",
        # C shows a loaded mesh file in place of the session until B makes a session of it.
        f"set mesh_file {KNOT}", "press load_mesh", "wait_idle 60", "frames 3", f"dump {d}/loaded_file.json"]
    script.remove("set_job_overrides")
    proc, d = start_gui("sessions", script, "--server", daemon.url)
    finish_gui(proc, d, timeout=280)
    snap = load_json(os.path.join(d, "snapshot.json"))
    sid = snap["session"]
    _, _, session = daemon.get(f"/api/v1/sessions/{sid}")
    check(session["name"] == "ball", f"rename: {session['name']}")
    _, _, snaps = daemon.get(f"/api/v1/sessions/{sid}/snapshots")
    check([s["name"] for s in snaps["snapshots"]] == ["before"], f"snapshots: {snaps}")
    running = load_json(os.path.join(d, "running.json"))
    check(running["version"] == 1 and running["view"]["triangles"] > snap["view"]["triangles"],
          f"the view did not follow the running evolution: {snap['view']['triangles']} -> {running['view']}")
    stopped = load_json(os.path.join(d, "stopped.json"))
    job = [j for j in stopped["jobs"] if j["op"] == "evolve"][0]
    _, _, job = daemon.get(f"/api/v1/jobs/{job['id']}")
    check(job["state"] == "succeeded" and stopped["version"] == 2, f"stopped job: {job['state']} v{stopped['version']}")
    evolution = job["result"]["evolution"]
    check(evolution["stop"] == "stopped" and 0 < evolution["steps"] < 100000, f"not stopped: {evolution}")
    restored = load_json(os.path.join(d, "restored.json"))
    check(restored["version"] == 3 and restored["view"]["mesh_version"] == 3, f"restore: {restored['version']}")
    redist = load_json(os.path.join(d, "redistanced.json"))
    check(redist["version"] == 4 and not redist["errors"], f"redistance: v{redist['version']} {redist['errors']}")
    _, _, with_points = daemon.get(f"/api/v1/sessions/{sid}")
    check(with_points.get("points"), f"the point cloud is not attached: {with_points.get('points')}")
    rec = load_json(os.path.join(d, "reconstructed.json"))
    check(rec["session"] not in ("", sid) and rec["view"]["triangles"] > 100 and not rec["errors"],
          f"reconstruct: {rec['session']} {rec['view']} {rec['errors']}")
    made = load_json(os.path.join(d, "job_file.json"))
    check(made["session"] not in ("", sid, rec["session"]) and made["view"]["triangles"] > 0,
          f"job file: {made['session']}")
    check(any(j["op"] == "job" or j["op"] == "evolve" for j in made["jobs"] if j["mine"]), f"jobs: {made['jobs']}")
    loaded = load_json(os.path.join(d, "loaded_file.json"))
    check(loaded["session"] == "" and loaded["view"]["triangles"] == 4160, f"C's mesh file: {loaded['view']}")
    deleted = load_json(os.path.join(d, "deleted.json"))
    status, _, _ = daemon.get(f"/api/v1/sessions/{made['session']}")
    check(status == 404 and deleted["session"] == "", f"delete: {status}, shown {deleted['session']!r}")


def scenario_roi():
    with_daemon(roi_with)


def roi_with(daemon):
    d = os.path.join(SCRATCH, "roi")
    # A session reconstructed from points over the API: the window shows its cloud when selected.
    status, _, up = upload(daemon, POINTS, "xyz")
    check(status == 201, f"upload the points: {status} {up}")
    status, _, job = daemon.post("/api/v1/sessions", {"upload": up["id"], "raster": {"resolution": 48}})
    job = daemon.wait_job(job["id"])
    check(job["state"] == "succeeded", f"reconstruct over the API: {job}")
    cloud_session = job["result"]["session"]
    script = [
        "wait_connected 30", "set primitive sphere", "set resolution 48", "press create_primitive", "wait_session 60",
        "wait_surface 60", f"dump {d}/sphere.json",
        # C then B with ROI: the knot's field becomes the sphere's region of influence.
        f"set mesh_file {KNOT}", "press load_mesh", "wait_idle 60", "frames 3", f"dump {d}/file.json",
        "set resolution 64", "set band 4", "click ROI", "click 'Compute distance field'", "wait_idle 120",
        "wait_session 60", "wait_surface 60", "frames 3", f"dump {d}/stored.json",
        # D: Point(ROI) with the surface hidden, then nothing with D at none.
        "click none", "click ROI##field", "wait_idle 60", "frames 20", f"screenshot {d}/roi.png", f"dump {d}/roi.json",
        "click none##field", "frames 5", f"screenshot {d}/none.png",
        # G with roi in the formula: the sphere is drawn toward the knot's surface.
        "set formula -roi", "set steps 10", "press evolve", "wait_idle 120", "expect_no_errors", f"dump {d}/evolved.json",
        # Remote frames follow D's ROI (PUT view roi).
        "click ROI##field", "set triangle_budget 1", "wait_surface 60", "frames 30", f"screenshot {d}/remote.png",
        f"dump {d}/remote.json", "set triangle_budget 2000000", "click none##field",
        # Clear ROI, then Store field as ROI (the session's own field).
        "click 'Clear ROI'", "wait_idle 30", "frames 3", f"dump {d}/cleared.json",
        "click 'Store field as ROI'", "wait_idle 30", "frames 3", f"dump {d}/own.json",
        # I: the reconstructed session's cloud, fetched from the daemon.
        f"select {cloud_session}", "set cloud 1", "wait_surface 60", "wait_idle 60", "frames 10",
        f"screenshot {d}/cloud.png", f"dump {d}/cloud.json"]
    proc, d = start_gui("roi", script, "--server", daemon.url)
    finish_gui(proc, d, timeout=280)
    sphere = load_json(os.path.join(d, "sphere.json"))["session"]
    check(load_json(os.path.join(d, "file.json"))["session"] == "", "C's mesh file is shown in place of the sphere")
    stored = load_json(os.path.join(d, "stored.json"))
    check(stored["session"] == sphere and not stored["errors"], f"the sphere is not shown again: {stored['session']} "
          f"{stored['errors']}")
    roi = stored["roi"]  # the sphere's description as the window had it
    check(isinstance(roi, dict) and roi.get("session") and roi["active_voxels"] > 5000, f"the sphere's roi: {roi}")
    status, _, _ = daemon.get(f"/api/v1/sessions/{roi['session']}")
    check(status == 404, f"the knot's session made for the ROI is not removed: {status}")
    _, _, sessions = daemon.get("/api/v1/sessions")
    check(sorted(x["id"] for x in sessions["sessions"]) == sorted([sphere, cloud_session]), f"sessions: {sessions}")
    shown = load_json(os.path.join(d, "roi.json"))
    check(shown["view"]["roi_loaded"] and shown["panel"]["field"] == 5, f"D's ROI: {shown['view']}")
    lit = scene_fraction(os.path.join(d, "roi.png"), lambda p: sum(p) > 200)
    empty = scene_fraction(os.path.join(d, "none.png"), lambda p: sum(p) > 200)
    print(f"ROI points cover {lit:.3f} of the scene, none {empty:.3f}")
    check(lit > 0.02 and empty < 0.002, f"ROI points: {lit:.3f} of the scene, with D at none {empty:.3f}")
    evolved = load_json(os.path.join(d, "evolved.json"))
    check(evolved["version"] > stored["version"], f"evolve with roi: v{stored['version']} -> v{evolved['version']}")
    _, _, history = daemon.get(f"/api/v1/sessions/{sphere}/history")
    check("-roi" in json.dumps(history), "the roi formula is not in the history")
    remote = load_json(os.path.join(d, "remote.json"))
    check(remote["view"]["remote"] and remote["view"]["frames_received"] > 0, f"remote frames: {remote['view']}")
    # Shading none and no cloud: what the daemon's frame shows is the ROI's points (roi=on in its view).
    lit_remote = scene_fraction(os.path.join(d, "remote.png"), lambda p: sum(p) > 200)
    check(lit_remote > 0.02, f"no ROI points in the remote frame ({lit_remote:.3f})")
    cleared = load_json(os.path.join(d, "cleared.json"))
    check(cleared["errors"] == [] and cleared["roi"] is None, f"Clear ROI: {cleared['roi']} {cleared['errors']}")
    own, final = load_json(os.path.join(d, "own.json")), daemon.get(f"/api/v1/sessions/{sphere}")[2]["roi"]
    check(isinstance(own["roi"], dict) and own["roi"].get("version") == own["version"] and final == own["roi"],
          f"Store field as ROI: {own['roi']}, the daemon's {final}")
    cloud = load_json(os.path.join(d, "cloud.json"))
    check(cloud["session"] == cloud_session and cloud["view"]["cloud_points"] == up["summary"]["points"],
          f"I: {cloud['view']}, uploaded {up['summary']}")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scenario_reconnect():
    port = free_port()
    data = os.path.join(SCRATCH, "data")
    daemon = Daemon(LEVELSETD, data, port=port)
    d = os.path.join(SCRATCH, "reconnect")
    script = ["wait_connected 30", "set primitive sphere", "set resolution 32", "press create_primitive",
              "wait_session 60", "wait_surface 60", f"dump {d}/connected.json",
              "wait_disconnected 60", "frames 3", f"screenshot {d}/banner.png", f"dump {d}/banner.json",
              "wait_connected 60", "wait_surface 60", "frames 3", f"screenshot {d}/reconnected.png",
              f"dump {d}/reconnected.json"]
    proc, d = start_gui("reconnect", script, "--server", daemon.url)
    try:
        wait_until(lambda: os.path.exists(os.path.join(d, "connected.json")), "the first dump", 120)
        daemon.kill()  # SIGKILL: the connection breaks with no goodbye
        wait_until(lambda: os.path.exists(os.path.join(d, "banner.json")), "the banner", 90)
        daemon = Daemon(LEVELSETD, data, port=port)
        finish_gui(proc, d)
    finally:
        if proc.poll() is None:
            proc.kill()
        daemon.stop()
    banner = load_json(os.path.join(d, "banner.json"))
    check(not banner["connected"] and "Connection lost" in banner["banner"], f"banner: {banner['banner']!r}")
    shown = red_pixels(os.path.join(d, "banner.png"), (PANEL_WIDTH, 0, WIDTH, 60))
    check(shown > 100, f"no red banner over the scene ({shown} red pixels)")
    after = load_json(os.path.join(d, "reconnected.json"))
    check(after["connected"] and after["banner"] == "", f"banner after the restart: {after['banner']!r}")
    check(red_pixels(os.path.join(d, "reconnected.png"), (PANEL_WIDTH, 0, WIDTH, 60)) < 20, "the banner stayed")
    check(after["session"] == banner["session"] and after["version"] >= 1, "the session did not come back")


def scenario_auth():
    tokens = os.path.join(SCRATCH, "tokens.txt")
    with open(tokens, "w") as f:
        f.write("rw-secret-token-123 rw\nro-secret-token-456 ro\n")
    daemon = Daemon(LEVELSETD, os.path.join(SCRATCH, "data"), "--token-file", tokens)
    d = os.path.join(SCRATCH, "auth")
    script = ["wait_disconnected 30", "frames 3", f"dump {d}/refused.json",
              f"connect {daemon.url} ro-secret-token-456", "wait_connected 30", "set primitive sphere",
              "set resolution 32", "press create_primitive", "wait_error forbidden 30", f"dump {d}/read_only.json",
              f"connect {daemon.url} rw-secret-token-123", "wait_connected 30", "clear_errors", "press create_primitive",
              "wait_session 60", "wait_surface 60", "expect_no_errors", f"dump {d}/read_write.json"]
    try:
        proc, d = start_gui("auth", script, "--server", daemon.url, "--token", "wrong-token")
        finish_gui(proc, d)
    finally:
        daemon.stop()
    refused = load_json(os.path.join(d, "refused.json"))
    check(not refused["connected"] and "refuses" in refused["banner"] and "unauthorized" in refused["banner"],
          f"banner for a wrong token: {refused['banner']!r}")
    ro = load_json(os.path.join(d, "read_only.json"))
    check(any("forbidden" in e and "read-only" in e for e in ro["errors"]), f"read-only token: {ro['errors']}")
    rw = load_json(os.path.join(d, "read_write.json"))
    check(rw["connected"] and rw["session"] and rw["view"]["triangles"] > 0, f"read-write token: {rw['view']}")
    settings = load_json(os.path.join(SCRATCH, "auth", "config", "levelset", "gui.json"))
    check(settings["token"] == "rw-secret-token-123", "the token given with Connect was not kept")


def process_alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def children_of(pid):
    out = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    if int(f.read().split(")")[-1].split()[1]) == pid:
                        out.append(int(entry))
            except (FileNotFoundError, ProcessLookupError, IndexError):
                pass
    return out


def scenario_embedded():
    # Run 1: the script quits; the panel's formula is remembered.
    script = ["wait_connected 60", "set formula '0.25 - H'", "set primitive torus", "set resolution 32",
              "press create_primitive", "wait_session 60", "wait_surface 60", f"dump {SCRATCH}/embedded/run1.json",
              # K and L from the keyboard: F12 writes the panel's PNG file, Ctrl+Q ends the window
              # (the wait after it would fail the script if it did not).
              "key f12", "frames 3", "key ctrl+q", "wait_error never-shown 60"]
    proc, d = start_gui("embedded", script)
    pid = wait_until(lambda: load_json(os.path.join(d, "run1.json"))["daemon_pid"]
                     if os.path.exists(os.path.join(d, "run1.json")) else 0, "the first dump", 120)
    check(process_alive(pid) and pid in children_of(proc.pid), f"levelsetd {pid} is not the window's child")
    with open(f"/proc/{pid}/cmdline", "rb") as f:
        check(b"levelsetd\0serve\0--port\x000" in f.read(), "not `levelsetd serve --port 0`")
    run1 = load_json(os.path.join(d, "run1.json"))
    finish_gui(proc, d)
    check(not process_alive(pid), f"levelsetd {pid} outlived the window")
    check(Image.open(os.path.join(d, "levelset-gui.png")).size == (WIDTH, HEIGHT), "F12 wrote no screenshot")
    with open(os.path.join(SCRATCH, "embedded", "state", "levelset-gui", "daemon.log")) as f:
        check("GET /api/v1" in f.read(), "the embedded daemon's log is not in $XDG_STATE_HOME/levelset-gui")
    port = int(run1["server"].rsplit(":", 1)[1])
    with socket.socket() as s:
        check(s.connect_ex(("127.0.0.1", port)) != 0, "the embedded daemon's port still answers")
    settings = load_json(os.path.join(SCRATCH, "embedded", "config", "levelset", "gui.json"))
    check(settings["panel"]["formula"] == "0.25 - H" and settings["server"] == "", f"settings: {settings}")
    check(settings["window"] == [WIDTH, HEIGHT], f"window size: {settings['window']}")
    mode = os.stat(os.path.join(SCRATCH, "embedded", "config", "levelset", "gui.json")).st_mode & 0o777
    check(mode == 0o600, f"the settings file (it may hold a token) has mode {oct(mode)}")

    # Run 2: the settings come back; SIGTERM to the window also stops its daemon.
    script = ["wait_connected 60", f"dump {SCRATCH}/embedded/run2.json", "frames 100000000"]
    proc, d = start_gui("embedded", script)
    path = os.path.join(d, "run2.json")
    wait_until(lambda: os.path.exists(path), "the second dump", 120)
    run2 = load_json(path)
    check(run2["panel"]["formula"] == "0.25 - H", f"the formula was not remembered: {run2['panel']['formula']}")
    check(run2["panel"]["primitive"] == "torus", "the primitive was not remembered")
    pid2 = run2["daemon_pid"]
    check(process_alive(pid2), "no second embedded daemon")
    proc.send_signal(signal.SIGTERM)
    rc = proc.wait(timeout=60)
    check(rc == 0, f"SIGTERM: the window exited {rc}")
    check(not process_alive(pid2), f"levelsetd {pid2} outlived the window's SIGTERM")

    # Run 3: no script: --screenshot shows the newest session (run 1's torus), writes and quits.
    shot = os.path.join(d, "shot.png")
    log = open(os.path.join(d, "run3.log"), "wb")
    rc = subprocess.run([GUI, "--screenshot", shot, "--width", str(WIDTH), "--height", str(HEIGHT)], stdout=log,
                        stderr=subprocess.STDOUT, env=gui_env("embedded"), cwd=d, timeout=120).returncode
    check(rc == 0, f"--screenshot run exited {rc}")
    stats = image_stats(shot)
    check(stats["surface_fraction"] > 0.02 and stats["panel_levels"] >= 8, f"--screenshot image: {stats}")


def main():
    for tool in (GUI, LEVELSETD):
        check(os.access(tool, os.X_OK), f"missing {tool}")
    check(os.environ.get("DISPLAY"), "no DISPLAY: run under xvfb-run -a")
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)
    t0 = time.monotonic()
    {"workflow": scenario_workflow, "sessions": scenario_sessions, "reconnect": scenario_reconnect, "roi": scenario_roi,
     "auth": scenario_auth, "embedded": scenario_embedded}[SCENARIO]()
    print(f"gui {SCENARIO}: ok in {time.monotonic() - t0:.1f} s")


if __name__ == "__main__":
    main()
