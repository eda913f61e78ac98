"""A generated point cloud (no test data needed): points uniform by area on a torus with their
outward normals, as "x y z nx ny nz" lines (the daemon's xyz upload format)."""
import math
import random


def torus_xyz(count=10000, major=1.0, minor=0.35, seed=18):
    rng = random.Random(seed)
    lines = []
    while len(lines) < count:
        u, v = rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)
        # Area element (major + minor cos v): keep v with that probability.
        if rng.uniform(0, major + minor) > major + minor * math.cos(v):
            continue
        n = (math.cos(v) * math.cos(u), math.cos(v) * math.sin(u), math.sin(v))
        p = ((major + minor * math.cos(v)) * math.cos(u), (major + minor * math.cos(v)) * math.sin(u), minor * math.sin(v))
        lines.append(" ".join(f"{c:.6f}" for c in p + n))
    return ("\n".join(lines) + "\n").encode()
