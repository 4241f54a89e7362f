#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""pointform.surfels (Python) vs Open3D's estimate_normals + orient_normals_consistent_tangent_plane
on the same numpy array, and the binding's own overhead over the C++ call.

Every measurement runs in a fresh child process (peak resident memory from os.wait4), on the
same N points of a unit sphere (a Fibonacci lattice, float32, deterministic), k = 16:

- pointform (Python): PointCloud(points) + pointform.surfels(cloud, k=16, radius_scale=1.0);
- pointform (C++): `pointform normals -k 16 --json` on the same points written as PLY: the
  sum of its compute_surfels stages (the same library call, without reading and writing);
- Open3D: PointCloud(Vector3dVector(points)), estimate_normals(KNN(16)),
  orient_normals_consistent_tangent_plane(16), under a time limit.

Quality: the share of normals pointing outwards (the sphere's truth), and the mean angle to the
radial direction up to sign. Run with Debian's interpreter from the repository root after
`bash scripts/setup.sh --peers` (Open3D) and a release build:

    /usr/bin/python3 bench/python/surfels_bench.py --points 1000000 --markdown bench/python/RESULTS.md
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent.parent
CLI = REPO / "build" / "release" / "apps" / "pointform" / "pointform"

POINTFORM_CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[2])
import numpy as np
import pointform
points = np.load(sys.argv[1])
import resource
baseline = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
t0 = time.perf_counter()
cloud = pointform.PointCloud(points)
t1 = time.perf_counter()
surfels, report = pointform.surfels(cloud, k=16, radius_scale=1.0)
t2 = time.perf_counter()
n = surfels.normals.astype(np.float64)
p = surfels.world()
cosine = np.sum(n * p, axis=1) / np.linalg.norm(p, axis=1)
print(json.dumps({"baseline_mib": baseline, "construct_s": t1 - t0, "surfels_s": t2 - t1, "total_s": t2 - t0,
                  "outward": float(np.mean(cosine > 0)), "angle_deg": float(np.degrees(np.mean(np.arccos(np.clip(np.abs(cosine), 0, 1))))),
                  "unoriented": report["unoriented"], "threads": pointform.thread_count()}))
"""

OPEN3D_CHILD = r"""
import json, sys, time
import numpy as np
import open3d as o3d
o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
points = np.load(sys.argv[1])
import resource
baseline = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
t0 = time.perf_counter()
cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points.astype(np.float64)))
t1 = time.perf_counter()
cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
t2 = time.perf_counter()
print(json.dumps({"phase": "estimated", "baseline_mib": baseline, "construct_s": t1 - t0, "estimate_s": t2 - t1}), flush=True)
cloud.orient_normals_consistent_tangent_plane(16)
t3 = time.perf_counter()
n = np.asarray(cloud.normals)
p = np.asarray(cloud.points)
cosine = np.sum(n * p, axis=1) / np.linalg.norm(p, axis=1)
print(json.dumps({"phase": "done", "baseline_mib": baseline, "construct_s": t1 - t0, "estimate_s": t2 - t1, "orient_s": t3 - t2,
                  "total_s": t3 - t0, "outward": float(np.mean(cosine > 0)),
                  "angle_deg": float(np.degrees(np.mean(np.arccos(np.clip(np.abs(cosine), 0, 1))))),
                  "open3d": o3d.__version__}))
"""


def sphere(n: int) -> np.ndarray:
    i = np.arange(n, dtype=np.float64) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / n)
    theta = np.pi * (1.0 + 5.0**0.5) * i
    return np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)],
                    axis=1).astype(np.float32)


def measure(kind: str, args: list[str], timeout: float) -> dict:
    """One measurement in a fresh `python3 -c` wrapper that reports the child's peak RSS."""
    wrapper = (
        "import json, os, resource, subprocess, sys, time\n"
        "start = time.perf_counter()\n"
        "child = subprocess.Popen(json.loads(sys.argv[1]), stdout=subprocess.PIPE, text=True)\n"
        "deadline = float(sys.argv[2])\n"
        "import threading\n"
        "timer = threading.Timer(deadline, child.kill); timer.start()\n"
        "out = child.stdout.read()\n"
        "_, status, usage = os.wait4(child.pid, 0)\n"
        "timer.cancel()\n"
        "print(json.dumps({'out': out, 'status': status, 'peak_mib': usage.ru_maxrss / 1024.0,"
        " 'wall_s': time.perf_counter() - start}))\n")
    done = subprocess.run([sys.executable, "-c", wrapper, json.dumps(args), str(timeout)],
                          capture_output=True, text=True, check=True)
    result = json.loads(done.stdout)
    lines = [json.loads(line) for line in result["out"].splitlines() if line.startswith("{")]
    record = {"kind": kind, "peak_mib": result["peak_mib"], "wall_s": result["wall_s"],
              "status": result["status"], "timed_out": result["status"] != 0}
    if lines:
        record.update(lines[-1])
    return record


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000000)
    parser.add_argument("--runs", type=int, default=3, help="runs of each pointform measurement (best kept)")
    parser.add_argument("--open3d-timeout", type=float, default=600.0)
    parser.add_argument("--no-open3d", action="store_true")
    parser.add_argument("--markdown", type=Path)
    args = parser.parse_args()

    folder = Path(tempfile.mkdtemp(prefix="pf_surfels_bench_"))
    points = sphere(args.points)
    npy = folder / "points.npy"
    np.save(npy, points)
    sys.path.insert(0, str(REPO))
    import pointform

    ply = folder / "points.ply"
    pointform.write(ply, pointform.PointCloud(points))

    python_runs, cpp_runs = [], []
    for _ in range(args.runs):  # interleaved, so that a busy moment hits both
        python_runs.append(measure("pointform-python", [sys.executable, "-c", POINTFORM_CHILD, str(npy), str(REPO)], 600))
        cli = subprocess.run([str(CLI), "normals", str(ply), "-o", str(folder / "out.ply"), "-k", "16",
                              "--radius-scale", "1", "--json"], capture_output=True, text=True, check=True)
        report = json.loads(cli.stdout)
        stages = {k: v for k, v in report["timings_s"].items() if k not in ("read", "write", "total")}
        cpp_runs.append({"surfels_s": sum(stages.values()), "stages": stages,
                         "peak_mib": report["peak_rss_bytes"] / 2**20})
    best_python = min(python_runs, key=lambda r: r["surfels_s"])
    best_cpp = min(cpp_runs, key=lambda r: r["surfels_s"])
    overhead = best_python["total_s"] / best_cpp["surfels_s"] - 1.0

    open3d = None
    if not args.no_open3d:
        open3d = measure("open3d", [sys.executable, "-c", OPEN3D_CHILD, str(npy)], args.open3d_timeout)

    cpu = platform.processor() or platform.machine()
    try:
        cpu = next(l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    lines = [
        f"# pointform.surfels (Python) vs Open3D, {args.points:,} points",
        "",
        f"- machine: {cpu}, {os.cpu_count()} logical CPUs; threads: all (pointform "
        f"{best_python.get('threads')}, Open3D OpenMP default); k = 16; points: a unit sphere "
        "(Fibonacci lattice), float32 numpy array; each run in a fresh process",
        f"- pointform: best of {args.runs} runs; Open3D: one run, time limit {args.open3d_timeout:.0f} s",
        "",
        "Peak MiB is the process's peak resident memory; 'before' is the same after the imports "
        "and loading the array, before the call.",
        "",
        "| tool | construct s | estimate + orient s | total s | peak MiB (before) | outward % | mean angle ° |",
        "|---|---|---|---|---|---|---|",
        f"| pointform (Python) | {best_python['construct_s']:.3f} | {best_python['surfels_s']:.3f} | "
        f"{best_python['total_s']:.3f} | {best_python['peak_mib']:.0f} ({best_python['baseline_mib']:.0f}) | "
        f"{100 * best_python['outward']:.2f} | {best_python['angle_deg']:.3f} |",
        f"| pointform (C++, `pointform normals`) | - | {best_cpp['surfels_s']:.3f} | {best_cpp['surfels_s']:.3f} | "
        f"{best_cpp['peak_mib']:.0f} (with reading the PLY) | - | - |",
    ]
    if open3d is not None:
        if open3d.get("phase") == "done":
            lines.append(
                f"| Open3D {open3d.get('open3d', '')} | {open3d['construct_s']:.3f} | "
                f"{open3d['estimate_s']:.3f} + {open3d['orient_s']:.3f} | {open3d['total_s']:.3f} | "
                f"{open3d['peak_mib']:.0f} ({open3d['baseline_mib']:.0f}) | {100 * open3d['outward']:.2f} | "
                f"{open3d['angle_deg']:.3f} |")
        else:
            estimated = (f"estimate {open3d['estimate_s']:.3f} s, then orient unfinished"
                         if open3d.get("phase") == "estimated" else "unfinished")
            lines.append(f"| Open3D | - | {estimated} | > {args.open3d_timeout:.0f} (killed) | "
                         f"{open3d['peak_mib']:.0f} at kill | - | - |")
    lines += [
        "",
        f"Binding overhead: Python total (PointCloud from the array + surfels) over the C++ call's "
        f"time = {100 * overhead:+.1f}% (target < 5%). All pointform runs, Python surfels s: "
        + ", ".join(f"{r['surfels_s']:.3f}" for r in python_runs)
        + "; C++ s: " + ", ".join(f"{r['surfels_s']:.3f}" for r in cpp_runs) + ".",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.markdown:
        args.markdown.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
