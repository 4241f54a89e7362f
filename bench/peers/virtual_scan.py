#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""A simulated multi-view range scan of a mesh, for held-out-style checks of `reconstruct`.

    virtual_scan.py MESH OUT.ply SEED [--views 6] [--resolution 260] [--noise 0.001]

The mesh is sampled densely (3M area-uniform points with their faces' normals); each of VIEWS
cameras, at a random direction 1.2-2 diagonals from the centre, keeps the nearest sample of every
pixel of a RESOLUTION² image (a z-buffer: occluded parts, such as the inside of grooves or a face
turned away from every camera, are not scanned), drops samples seen at grazing angles (always
below cos 0.15, and with probability 1 - 1.6 cos above), and moves each along its ray by a
Gaussian range error of NOISE times the range. Five disks of 2.5% of the diagonal are cut out
and 40 stray returns added (1% of the diagonal off the surface). The density is uneven: faces
seen head-on by several cameras get many samples, faces seen at a slant few. Writes binary PLY
positions only (float), what `pointform` and the peers read.

Open3D's RaycastingScene.cast_rays is not used: in python3-open3d 0.16 here it returned no hit
even for a ray through the centre of a sphere.
"""

from __future__ import annotations

import argparse

import numpy as np


def triangle_samples(vertices: np.ndarray, faces: np.ndarray, count: int,
                     rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """`count` area-uniform samples of the triangles `faces` (indices into `vertices`), from
    `rng`, with their triangles' unit normals."""
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces)
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    cross = np.cross(b - a, c - a)
    length = np.linalg.norm(cross, axis=1)
    area = 0.5 * length
    face = rng.choice(len(faces), size=count, p=area / area.sum())
    u, v = rng.uniform(size=(2, len(face)))
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    points = a[face] + u[:, None] * (b[face] - a[face]) + v[:, None] * (c[face] - a[face])
    normals = cross[face] / np.where(length[face] > 0, length[face], 1.0)[:, None]
    return points, normals


def surface_samples(mesh, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """triangle_samples() of an Open3D triangle mesh (Open3D's sampler has its own generator)."""
    return triangle_samples(np.asarray(mesh.vertices), np.asarray(mesh.triangles), count, rng)


def scan(mesh_path: str, seed: int, views: int = 6, resolution: int = 260,
         noise: float = 0.001) -> np.ndarray:
    """scan_triangles() of a mesh file (read with Open3D)."""
    import open3d as o3d

    mesh = o3d.io.read_triangle_mesh(mesh_path)
    return scan_triangles(np.asarray(mesh.vertices), np.asarray(mesh.triangles), seed, views,
                          resolution, noise)


def scan_triangles(vertices: np.ndarray, faces: np.ndarray, seed: int, views: int = 6,
                   resolution: int = 260, noise: float = 0.001) -> np.ndarray:
    """The simulated scan of a triangle mesh (the module's docstring): numpy only."""
    rng = np.random.default_rng(seed)
    vertices = np.asarray(vertices, dtype=np.float64)
    low, high = vertices.min(0), vertices.max(0)
    centre = (low + high) / 2
    diag = float(np.linalg.norm(high - low))
    points, normals = triangle_samples(vertices, faces, 3_000_000, rng)
    parts = []
    for _ in range(views):
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        eye = centre + direction * diag * rng.uniform(1.2, 2.0)
        forward = centre - eye
        distance = float(np.linalg.norm(forward))
        forward /= distance
        up = np.array([0.0, 0.0, 1.0]) if abs(forward[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        right = np.cross(forward, up)
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        relative = points - eye
        depth = relative @ forward
        half = 0.6 * diag / distance  # the half-width of the image at unit depth
        with np.errstate(divide="ignore", invalid="ignore"):
            x = (relative @ right) / depth / half
            y = (relative @ up) / depth / half
        px = np.floor((x + 1) / 2 * resolution)
        py = np.floor((y + 1) / 2 * resolution)
        seen = (depth > 0) & (px >= 0) & (px < resolution) & (py >= 0) & (py < resolution)
        index = np.nonzero(seen)[0]
        pixel = (py[index] * resolution + px[index]).astype(np.int64)
        order = np.lexsort((depth[index], pixel))
        index, pixel = index[order], pixel[order]
        first = np.ones(len(pixel), bool)
        first[1:] = pixel[1:] != pixel[:-1]
        front = index[first]
        ray = points[front] - eye
        length = np.linalg.norm(ray, axis=1)
        ray /= length[:, None]
        cosine = -np.sum(normals[front] * ray, axis=1)
        keep = (cosine > 0.15) & (rng.uniform(size=len(front)) < np.clip(1.6 * cosine, 0, 1))
        ray, length = ray[keep], length[keep]
        length = length + rng.normal(scale=noise * length, size=len(length))
        parts.append(eye + ray * length[:, None])
    cloud = np.concatenate(parts)
    for _ in range(5):
        hole = cloud[rng.integers(len(cloud))]
        cloud = cloud[np.linalg.norm(cloud - hole, axis=1) > 0.025 * diag]
    strays = cloud[rng.integers(len(cloud), size=40)] + rng.normal(scale=0.01 * diag, size=(40, 3))
    return np.concatenate([cloud, strays])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("out")
    ap.add_argument("seed", type=int)
    ap.add_argument("--views", type=int, default=6)
    ap.add_argument("--resolution", type=int, default=260)
    ap.add_argument("--noise", type=float, default=0.001,
                    help="standard deviation of the range error, as a fraction of the range")
    args = ap.parse_args()
    cloud = scan(args.mesh, args.seed, args.views, args.resolution, args.noise).astype("<f4")
    with open(args.out, "wb") as out:
        out.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n" % len(cloud)).encode())
        out.write(cloud.tobytes())
    print(f"{len(cloud)} samples")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
