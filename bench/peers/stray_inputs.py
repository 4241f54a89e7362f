#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Inputs for the stray-sample and merged-scan checks of bench/peers/RESULTS_reconstruct.md.

    stray_inputs.py merge CONF OUT.ply          range scans aligned by a Stanford .conf file
    stray_inputs.py strays IN.ply OUT.ply [--clusters 30] [--min 3] [--max 15] [--seed 1]
    stray_inputs.py uneven IN.ply OUT.ply --keep F [--seed 3]

`merge` reads every `bmesh FILE tx ty tz qx qy qz qw` line of CONF whose FILE exists beside it
and writes the vertices as p' = R(q)^T p + t (the poses of the Stanford bunny's bun.conf). `strays`
adds clusters of stray samples: each around a sample moved outwards from the centroid by 2-15%
of the bounding-box diagonal (plus a 2% jitter), of MIN to MAX Gaussian samples with a spread of
0.2-1% of the diagonal. `uneven` keeps every sample with z > 0 and a fraction F of the others.
All write binary PLY positions only (float), what `pointform` and the peers read.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from plyio import read_ply


def write_points(path: Path, points: np.ndarray) -> None:
    points = np.asarray(points, dtype="<f4")
    with open(path, "wb") as out:
        out.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\n"
                   "property float x\nproperty float y\nproperty float z\nend_header\n"
                   % len(points)).encode())
        out.write(points.tobytes())


def positions(path: Path) -> np.ndarray:
    v = read_ply(path)
    return np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)


def rotation(qx: float, qy: float, qz: float, qw: float) -> np.ndarray:
    x, y, z, w = qx, qy, qz, qw
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def merge(conf: Path, out: Path) -> None:
    parts = []
    for line in conf.read_text().splitlines():
        words = line.split()
        if len(words) != 9 or words[0] != "bmesh" or not (conf.parent / words[1]).exists():
            continue
        t = np.array([float(w) for w in words[2:5]])
        r = rotation(*(float(w) for w in words[5:9]))
        parts.append(positions(conf.parent / words[1]) @ r + t)  # R^T p + t, row by row
        print(f"{words[1]}: {len(parts[-1])} samples")
    write_points(out, np.concatenate(parts))


def strays(src: Path, out: Path, clusters: int, low: int, high: int, seed: int) -> None:
    p = positions(src)
    rng = np.random.default_rng(seed)
    diag = float(np.linalg.norm(p.max(0) - p.min(0)))
    centroid = p.mean(0)
    added = []
    for _ in range(clusters):
        at = p[rng.integers(len(p))]
        outwards = (at - centroid) / np.linalg.norm(at - centroid)
        centre = (at + outwards * diag * rng.uniform(0.02, 0.15) +
                  rng.normal(size=3) * diag * 0.02)
        count = int(rng.integers(low, high + 1))
        spread = diag * rng.uniform(0.002, 0.01)
        added.append(centre + rng.normal(size=(count, 3)) * spread)
    added = np.concatenate(added)
    write_points(out, np.concatenate([p, added]))
    print(f"{len(added)} strays added to {len(p)} samples")


def uneven(src: Path, out: Path, keep: float, seed: int) -> None:
    p = positions(src)
    rng = np.random.default_rng(seed)
    kept = p[(p[:, 2] > 0) | (rng.random(len(p)) < keep)]
    write_points(out, kept)
    print(f"{len(kept)} of {len(p)} samples kept")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    m = sub.add_parser("merge")
    m.add_argument("conf", type=Path)
    m.add_argument("out", type=Path)
    s = sub.add_parser("strays")
    s.add_argument("src", type=Path)
    s.add_argument("out", type=Path)
    s.add_argument("--clusters", type=int, default=30)
    s.add_argument("--min", type=int, default=3)
    s.add_argument("--max", type=int, default=15)
    s.add_argument("--seed", type=int, default=1)
    u = sub.add_parser("uneven")
    u.add_argument("src", type=Path)
    u.add_argument("out", type=Path)
    u.add_argument("--keep", type=float, required=True)
    u.add_argument("--seed", type=int, default=3)
    args = ap.parse_args()
    if args.command == "merge":
        merge(args.conf, args.out)
    elif args.command == "strays":
        strays(args.src, args.out, args.clusters, args.min, args.max, args.seed)
    else:
        uneven(args.src, args.out, args.keep, args.seed)


if __name__ == "__main__":
    main()
