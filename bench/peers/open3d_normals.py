#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Open3D peer for run_normals_bench.py (run with Debian's /usr/bin/python3 + python3-open3d).

Usage: open3d_normals.py IN.ply OUT.ply [-k K]

Reads the points (any normals in the file are dropped: Open3D's estimate_normals would
otherwise orient the new normals towards the old ones), estimates normals with
PointCloud.estimate_normals(KDTreeSearchParamKNN(k)), orients them with
orient_normals_consistent_tangent_plane(k), and writes a binary PLY in input order. Prints
one JSON object on stdout with the time of each stage. The thread count comes from
OMP_NUM_THREADS (Open3D parallelises with OpenMP).
"""

import argparse
import json
import sys
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("input")
    parser.add_argument("output")
    parser.add_argument("-k", type=int, default=16)
    args = parser.parse_args()

    clock = time.perf_counter
    t0 = clock()
    import open3d as o3d  # imported here so that its import time is reported on its own

    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    t_import = clock()

    cloud = o3d.io.read_point_cloud(args.input)
    if cloud.is_empty():
        print(f"open3d_normals: cannot read points from '{args.input}'", file=sys.stderr)
        return 1
    if cloud.has_normals():
        cloud = o3d.geometry.PointCloud(cloud.points)
    t_read = clock()

    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(args.k))
    t_estimate = clock()

    cloud.orient_normals_consistent_tangent_plane(args.k)
    t_orient = clock()

    if not o3d.io.write_point_cloud(args.output, cloud, write_ascii=False):
        print(f"open3d_normals: cannot write '{args.output}'", file=sys.stderr)
        return 1
    t_write = clock()

    report = {
        "tool": "open3d",
        "open3d_version": o3d.__version__,
        "points": len(cloud.points),
        "unoriented": None,  # Open3D does not report points it could not orient
        "k": args.k,
        "timings_s": {
            "import": t_import - t0,
            "read": t_read - t_import,
            "estimate": t_estimate - t_read,
            "orient": t_orient - t_estimate,
            "write": t_write - t_orient,
            "total": t_write - t0,
        },
    }
    print(json.dumps(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
