# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Point-to-mesh distances side by side: pointform's TriangleBvh (what `pointform distance`
measures with) against Open3D's RaycastingScene.compute_distance (Embree), on the same meshes
and the same query points, in one run.

For every mesh, two query sets of --count points (default 1M), drawn once with numpy:
- near: area-uniform samples of the mesh, each moved along a random direction by up to 1% of
  the diagonal (the case of measuring a reconstruction against its samples or a truth);
- box: uniform in the bounding box grown by 10% on every side (farther from the surface).

Times exclude reading the files: pointform's is the hierarchy's construction plus the queries
(bench/peers/mesh_distance), Open3D's the scene's construction plus compute_distance (Embree
builds its hierarchy on the first query). Both use all cores. The largest difference between the
two tools' distances over all points is reported relative to the mesh's diagonal (Open3D
computes in single precision, pointform in double).

    cmake --preset bench && cmake --build --preset bench
    /usr/bin/python3 bench/peers/run_distance_bench.py --markdown bench/peers/RESULTS_distance.md

The meshes: the two shipped in data/meshes, and the marching-cubes surface of the bunny scan at
--resolution 400 made by `pointform mc` in the run (about 0.5M triangles).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))
from plyio import write_ply  # noqa: E402
from run_surface_bench import isolated  # noqa: E402


def area_samples(vertices: np.ndarray, triangles: np.ndarray, count: int,
                 rng: np.random.Generator) -> np.ndarray:
    a, b, c = (vertices[triangles[:, i]] for i in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    face = rng.choice(len(triangles), size=count, p=area / area.sum())
    r1 = np.sqrt(rng.random(count))[:, None]
    r2 = rng.random(count)[:, None]
    return (1 - r1) * a[face] + r1 * (1 - r2) * b[face] + r1 * r2 * c[face]


def open3d_distances(mesh_path: str, points_path: str) -> dict:
    """Open3D's distances from the points to the mesh, timed from the scene's construction."""
    import open3d as o3d

    mesh = o3d.io.read_triangle_mesh(mesh_path)
    points = np.load(points_path).astype(np.float32)
    start = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    distances = scene.compute_distance(o3d.core.Tensor(points)).numpy()
    elapsed = time.perf_counter() - start
    np.save(points_path + ".o3d.npy", distances.astype(np.float64))
    return {"o3d_s": elapsed}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pointform", default=str(ROOT / "build/bench/apps/pointform/pointform"))
    ap.add_argument("--mesh-distance", default=str(ROOT / "build/bench/bench/peers/mesh_distance"))
    ap.add_argument("--count", type=int, default=1000000)
    ap.add_argument("--repeat", type=int, default=3, help="best of R runs of each tool")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--markdown", help="write the table to this file too")
    args = ap.parse_args(argv)
    import open3d as o3d

    rng = np.random.default_rng(args.seed)
    rows = []
    with tempfile.TemporaryDirectory(prefix="pf-distance-") as tmp:
        work = Path(tmp)
        mc_mesh = work / "bunny_mc400.ply"
        subprocess.run([args.pointform, "-q", "mc", str(ROOT / "data/bunny/bun_zipper.ply"),
                        "-o", str(mc_mesh), "--resolution", "400"], check=True)
        meshes = [("bunny_uniform.off", ROOT / "data/meshes/bunny_uniform.off"),
                  ("spot.obj", ROOT / "data/meshes/spot.obj"),
                  ("bunny scan, mc 400", mc_mesh)]
        for name, path in meshes:
            legacy = o3d.io.read_triangle_mesh(str(path))
            vertices = np.asarray(legacy.vertices, dtype=np.float64)
            triangles = np.asarray(legacy.triangles)
            lo, hi = vertices.min(0), vertices.max(0)
            diag = float(np.linalg.norm(hi - lo))
            near = area_samples(vertices, triangles, args.count, rng)
            direction = rng.normal(size=near.shape)
            direction /= np.linalg.norm(direction, axis=1)[:, None]
            near += direction * (0.01 * diag * rng.random(args.count))[:, None]
            grow = 0.1 * (hi - lo)
            box = lo - grow + rng.random((args.count, 3)) * (hi - lo + 2 * grow)
            for queries, points in (("near", near), ("box", box)):
                ply = work / "points.ply"
                # Single-precision positions, so both tools measure from the same points.
                points = points.astype(np.float32)
                write_ply(ply, {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]})
                npy = str(work / "points.npy")
                np.save(npy, points)
                out = work / "pf.f64"
                pf = []
                for _ in range(args.repeat):
                    done = subprocess.run([args.mesh_distance, str(path), str(ply), str(out)],
                                          check=True, capture_output=True, text=True)
                    report = json.loads(done.stdout)
                    pf.append(report["build_s"] + report["query_s"])
                o3d_times = []
                for _ in range(args.repeat):
                    result = isolated(open3d_distances, str(path), npy)
                    if "o3d_s" not in result:
                        break
                    o3d_times.append(result["o3d_s"])
                row = {"mesh": name, "triangles": report["triangles"], "queries": queries,
                       "points": report["points"], "pointform_s": min(pf),
                       "threads": report["threads"]}
                if o3d_times:
                    ours = np.fromfile(out, dtype="<f8")
                    theirs = np.load(npy + ".o3d.npy")
                    row.update({"open3d_s": min(o3d_times),
                                "speedup": min(o3d_times) / min(pf),
                                "max_diff_rel_diag": float(np.abs(ours - theirs).max()) / diag,
                                "max_distance_rel_diag": float(ours.max()) / diag})
                else:
                    row["open3d"] = result.get("isolated", "failed")
                rows.append(row)
                print(json.dumps(row), flush=True)
    header = ("| mesh | triangles | queries | pointform s | Open3D s | speed-up | "
              "largest difference / diagonal |\n|---|---|---|---|---|---|---|")
    lines = [header]
    for r in rows:
        if "open3d_s" in r:
            lines.append(f"| {r['mesh']} | {r['triangles']:,} | {r['queries']} {r['points']:,} | "
                         f"{r['pointform_s']:.3f} | {r['open3d_s']:.3f} | {r['speedup']:.2f}× | "
                         f"{r['max_diff_rel_diag']:.1e} |")
        else:
            lines.append(f"| {r['mesh']} | {r['triangles']:,} | {r['queries']} {r['points']:,} | "
                         f"{r['pointform_s']:.3f} | {r['open3d']} | – | – |")
    table = "\n".join(lines)
    print(table)
    if args.markdown:
        intro = (
            "# Point-to-mesh distances: pointform against Open3D's RaycastingScene\n\n"
            f"`/usr/bin/python3 bench/peers/run_distance_bench.py --count {args.count} --repeat "
            f"{args.repeat}` on {time.strftime('%Y-%m-%d')}, {os.cpu_count()} logical CPUs, "
            f"both tools on all of them; best of {args.repeat} runs of each tool. Seconds from "
            "the hierarchy's construction through the last query (files already read); the last "
            "column is the largest difference between the two tools' distances over all the "
            "points, relative to the mesh's bounding-box diagonal (Open3D computes in single "
            "precision). Queries: near, area-uniform samples moved by up to 1% of the diagonal "
            "in random directions; box, uniform in the bounding box grown by 10% on every side. "
            "Both query sets are in random order.\n\n")
        Path(args.markdown).write_text(intro + table + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
