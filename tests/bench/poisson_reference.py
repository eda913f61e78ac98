#!/usr/bin/python3
"""Reference for bench_reconstruct: Open3D's screened Poisson on a point file (no normals given).

usage: poisson_reference.py POINTS.xyz OUT.ply DEPTH K
Estimates normals, orients them (consistent tangent plane, K neighbours), runs Poisson at
DEPTH, writes the mesh and prints one JSON line: {"seconds": T, "mesh": OUT, "triangles": N}.
T covers normals, orientation and Poisson (not the file reading).
"""
import json
import sys
import time

import open3d as o3d


def main():
    points, out, depth, k = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    pcd = o3d.io.read_point_cloud(points, format="xyz")
    t0 = time.perf_counter()
    pcd.estimate_normals()
    pcd.orient_normals_consistent_tangent_plane(k)
    mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=depth)
    seconds = time.perf_counter() - t0
    o3d.io.write_triangle_mesh(out, mesh)
    print(json.dumps({"seconds": seconds, "mesh": out, "triangles": len(mesh.triangles)}))


if __name__ == "__main__":
    main()
