# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Open3D surface reconstruction peer: Poisson (depth D) or ball pivoting on oriented surfels.

Usage: open3d_surface.py IN.ply OUT.ply poisson DEPTH | bpa [--estimate-normals K]
Reads x y z nx ny nz from IN (the same surfels pointform gets), writes the mesh, prints a JSON
report with the reconstruction time on stdout. With --estimate-normals K it reads raw points,
estimates normals from K neighbours and orients them (Open3D's consistent tangent plane
propagation) first, and the time includes that: end to end from raw points.
"""

import json
import sys
import time

import numpy as np
import open3d as o3d

from plyio import read_ply


def main(argv):
    estimate_k = None
    if "--estimate-normals" in argv:
        at = argv.index("--estimate-normals")
        estimate_k = int(argv[at + 1])
        argv = argv[:at] + argv[at + 2:]
    src, dst, method = argv[1], argv[2], argv[3]
    v = read_ply(src)
    pcd = o3d.geometry.PointCloud()
    pcd.points = o3d.utility.Vector3dVector(np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64))
    start = time.perf_counter()
    if estimate_k is None:
        pcd.normals = o3d.utility.Vector3dVector(np.stack([v["nx"], v["ny"], v["nz"]], 1).astype(np.float64))
    else:
        pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(estimate_k))
        pcd.orient_normals_consistent_tangent_plane(estimate_k)
    if method == "poisson":
        mesh, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd, depth=int(argv[4]))
    elif method == "bpa":
        spacing = float(np.mean(pcd.compute_nearest_neighbor_distance()))
        radii = o3d.utility.DoubleVector([1.5 * spacing, 3.0 * spacing, 6.0 * spacing])
        mesh = o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(pcd, radii)
    else:
        raise SystemExit(f"unknown method {method}")
    seconds = time.perf_counter() - start
    o3d.io.write_triangle_mesh(dst, mesh)
    print(json.dumps({"timings_s": {"surface": seconds, "total": seconds},
                      "vertices": len(mesh.vertices), "faces": len(mesh.triangles)}))


if __name__ == "__main__":
    main(sys.argv)
