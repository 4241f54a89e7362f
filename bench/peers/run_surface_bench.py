# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Side-by-side benchmark of surfaces from oriented samples: pointform mc against Open3D's
Poisson (several depths) and ball pivoting, on the same surfels, in one run.

For every input (an analytic shape sampled by `pointform sample`, clean or with noise and
holes) it makes surfels once with `pointform normals`, gives the same surfels to every tool,
and reports per tool: reconstruction time, peak memory (/usr/bin/time), vertex count, and the
accuracy against the true analytic surface: symmetric Hausdorff, Chamfer (mean both ways) and
F-score at 0.5% and 1% of the diagonal. Distances from the mesh to the truth are exact
(analytic); from the truth to the mesh they are exact point-to-triangle distances by `pointform
distance`, cross-checked against Open3D's RaycastingScene on the same points ("pf/o3d max
dist": the ratio of the two maxima; empty where Debian's Open3D aborted inside it). "Spurious"
is the share of the mesh's area farther than 1% of the diagonal from every input sample:
surface where there are no samples.

Run with /usr/bin/python3 (Debian's python3-open3d):
  /usr/bin/python3 bench/peers/run_surface_bench.py --pointform build/release/apps/pointform/pointform
"""

from __future__ import annotations

import argparse
import faulthandler
import functools
import hashlib
import multiprocessing
import json
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import open3d as o3d

sys.path.insert(0, str(Path(__file__).resolve().parent))
from plyio import read_ply  # noqa: E402
from run_normals_bench import run_measured  # noqa: E402
from virtual_scan import surface_samples  # noqa: E402

HERE = Path(__file__).resolve().parent
# "strays" (not run by default): 1% stray points through the bounding box grown by 30%, the
# nearer within a few spacings of the surface (near-surface stray returns).
VARIANTS = {"clean": [], "noisy+holes": ["--noise", "0.002", "--holes", "8", "--hole-radius", "0.04"],
            "strays": ["--strays", "0.01"]}


# Shape::Blobby and Shape::Part of src/geometry/shapes.cpp (keep in sync).
BLOBBY = [((0.0, 0.0, 0.0), 0.8), ((0.95, 0.1, 0.0), 0.5), ((-0.8, 0.45, 0.15), 0.55),
          ((0.1, 0.9, -0.35), 0.45), ((0.05, -0.35, 0.9), 0.45), ((-0.35, -0.85, -0.3), 0.5)]
PART_ADDED = [("box", (-1.0, -0.6, -0.3), (1.0, 0.6, 0.3)), ("cylinder", (0.5, 0.0, 0.1), (0.35, 0.0, 0.7))]
PART_REMOVED = [("cylinder", (-0.5, 0.0, -1.0), (0.25, 0.0, 1.0))]


def _box_sdf(p, lo, hi):
    c = 0.5 * (np.array(lo) + np.array(hi))
    e = np.abs(p - c) - 0.5 * (np.array(hi) - np.array(lo))
    return np.linalg.norm(np.maximum(e, 0.0), axis=1) + np.minimum(e.max(1), 0.0)


def _cylinder_sdf(p, lo, hi):
    d = np.stack([np.hypot(p[:, 0] - lo[0], p[:, 1] - lo[1]) - hi[0],
                  np.abs(p[:, 2] - 0.5 * (lo[2] + hi[2])) - 0.5 * (hi[2] - lo[2])], 1)
    return np.linalg.norm(np.maximum(d, 0.0), axis=1) + np.minimum(d.max(1), 0.0)


def _primitive_sdf(q, p):
    return _box_sdf(p, q[1], q[2]) if q[0] == "box" else _cylinder_sdf(p, q[1], q[2])


def _blobby_distance(p: np.ndarray) -> np.ndarray:
    """Exact distance to the boundary of the union of balls, whose pairwise intersection circles
    meet no third ball: the nearest boundary point is a radial projection onto a sphere that no
    other ball covers, or a point of an intersection circle."""
    centers = np.array([c for c, _ in BLOBBY])
    radii = np.array([r for _, r in BLOBBY])
    best = np.full(len(p), np.inf)
    for i, (c, r) in enumerate(zip(centers, radii)):
        v = p - c
        norm = np.maximum(np.linalg.norm(v, axis=1), 1e-300)
        q = c + r * v / norm[:, None]
        covered = np.zeros(len(p), bool)
        for j, (cj, rj) in enumerate(zip(centers, radii)):
            if j != i:
                covered |= np.linalg.norm(q - cj, axis=1) < rj
        best = np.where(covered, best, np.minimum(best, np.abs(norm - r)))
        for j in range(i + 1, len(radii)):
            axis = centers[j] - c
            d = np.linalg.norm(axis)
            if d >= r + radii[j] or d <= abs(r - radii[j]):
                continue
            axis /= d
            t = (d * d + r * r - radii[j] ** 2) / (2 * d)
            ring = np.sqrt(r * r - t * t)
            w = p - (c + t * axis)
            h = w @ axis
            rho = np.linalg.norm(w - h[:, None] * axis, axis=1)
            best = np.minimum(best, np.hypot(rho - ring, h))
    return best


# The Stanford bunny's own reconstruction: the truth of the shipped scan (its vertices).
BUNNY_MESH = HERE.parent.parent / "data" / "bunny" / "bun_zipper.ply"
# The thickness of the "thin-plate" shape (`pointform sample plate --thickness`): 2.2 sample
# spacings at 100k samples, where a neighbourhood of 16 reaches the far face.
THIN_PLATE = 0.02


def sample_args(shape: str) -> list[str]:
    """The arguments of `pointform sample` that draw `shape` (an analytic shape's name, or
    "thin-plate")."""
    return ["plate", "--thickness", str(THIN_PLATE)] if shape == "thin-plate" else [shape]


# Meshes that run_reconstruct_bench.py scans (virtual_scan.py): each is the truth of its scans.
SCANNED_MESHES = {"fandisk": HERE.parent.parent / "data" / "meshes" / "fandisk.obj",
                  "spot": HERE.parent.parent / "data" / "meshes" / "spot.obj",
                  "teapot": HERE.parent.parent / "data" / "meshes" / "teapot.obj"}

# Machined parts written in the modeling language (`pointform model`, marching cubes of 400
# cells along the longest side), scanned like the meshes above: large flat faces seen head-on
# by some cameras and at a slant by the rest, bores and bolt holes, a thin fin. A bracket (a
# plate with an upright, a bore through the plate, a slot through the upright), a flange (a disc
# with a boss, a bore through both and four bolt holes) and a block with a fin 0.06 thick and a
# round boss.
CAD_PARTS = {
    "bracket": "difference(union(box([-1,-0.6,-0.2],[1,0.6,0.2]), box([-1,-0.6,0.2],[-0.6,0.6,1.0])), "
               "union(cylinder([0.5,0,-0.5],[0.5,0,0.5],0.22), box([-1.2,-0.15,0.45],[-0.4,0.15,0.8])))",
    "flange": "difference(union(cylinder([0,0,-0.2],[0,0,0.2],1.0), "
              "cylinder([0,0,0.1],[0,0,0.9],0.45)), "
              "union(cylinder([0,0,-0.5],[0,0,1.2],0.25), cylinder([0.72,0,-0.5],[0.72,0,0.5],0.09), "
              "cylinder([-0.72,0,-0.5],[-0.72,0,0.5],0.09), cylinder([0,0.72,-0.5],[0,0.72,0.5],0.09), "
              "cylinder([0,-0.72,-0.5],[0,-0.72,0.5],0.09)))",
    "finblock": "union(box([-1,-0.5,-0.3],[1,0.5,0.3]), box([-0.03,-0.5,0.25],[0.03,0.5,0.9]), "
                "cylinder([0.6,0,0.25],[0.6,0,0.7],0.2))",
}
CAD_CACHE = Path(tempfile.gettempdir()) / "pointform-bench-cad"
for _name, _expression in CAD_PARTS.items():
    # Named by the expression, so that an edited part is built again.
    SCANNED_MESHES[_name] = CAD_CACHE / f"{_name}-{hashlib.sha256(_expression.encode()).hexdigest()[:12]}.ply"


def ensure_cad_part(shape: str, pointform) -> None:
    """Builds the mesh of a CAD part (CAD_PARTS) with `pointform model` unless it is there."""
    if shape not in CAD_PARTS or SCANNED_MESHES[shape].exists():
        return
    CAD_CACHE.mkdir(parents=True, exist_ok=True)
    partial = SCANNED_MESHES[shape].with_suffix(".partial.ply")
    status = run_measured([pointform, "model", CAD_PARTS[shape], "-o", partial, "--resolution",
                           "400", "--json"], os.environ.copy(), 600, CAD_CACHE / shape)[0]
    if status != "ok":
        raise RuntimeError(f"pointform model of {shape} failed ({status})")
    partial.replace(SCANNED_MESHES[shape])


@functools.lru_cache(maxsize=None)
def _mesh_truth(mesh_path: Path):
    """A truth mesh's Open3D RaycastingScene and its triangles' unit normals, built once a
    process (an evaluation asks for both the distances and the normals)."""
    loaded = o3d.io.read_triangle_mesh(str(mesh_path))
    mesh = o3d.geometry.TriangleMesh(loaded.vertices, loaded.triangles)
    mesh.compute_triangle_normals()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    return scene, np.asarray(mesh.triangle_normals)


def _mesh_distance(mesh_path: Path, p: np.ndarray) -> np.ndarray:
    """Exact point-to-triangle distance to a mesh (Open3D's RaycastingScene)."""
    scene = _mesh_truth(mesh_path)[0]
    return scene.compute_distance(o3d.core.Tensor(p.astype(np.float32))).numpy().astype(np.float64)


def _truth_mesh_path(shape: str):
    """The mesh that is the truth of `shape`, or None for an analytic shape."""
    return BUNNY_MESH if shape == "bunny" else SCANNED_MESHES.get(shape)


def _signed_distance(shape: str, p: np.ndarray) -> np.ndarray:
    """Signed distance to an analytic shape, negative inside (exact; for the part, the
    distance bound of its CSG of exact primitive distances, exact but within its concave
    creases and the hole's rims, where it may be lower in magnitude)."""
    if shape == "sphere":
        return np.linalg.norm(p, axis=1) - 1.0
    if shape == "torus":
        rho = np.hypot(p[:, 0], p[:, 1])
        return np.hypot(rho - 1.0, p[:, 2]) - 0.35
    if shape == "two-spheres":
        c = np.where(p[:, :1] > 0, 1.6, -1.6)
        return np.linalg.norm(p - np.concatenate([c, np.zeros((len(p), 2))], 1), axis=1) - 1.0
    if shape == "plate":
        return _box_sdf(p, (-1.0, -1.0, -0.025), (1.0, 1.0, 0.025))
    if shape == "thin-plate":
        return _box_sdf(p, (-1.0, -1.0, -0.5 * THIN_PLATE), (1.0, 1.0, 0.5 * THIN_PLATE))
    if shape == "blobby":
        inside = np.any([np.linalg.norm(p - np.array(c), axis=1) < r for c, r in BLOBBY], axis=0)
        return np.where(inside, -1.0, 1.0) * _blobby_distance(p)
    if shape == "part":
        value = np.min([_primitive_sdf(q, p) for q in PART_ADDED], axis=0)
        return np.maximum(value, -np.min([_primitive_sdf(q, p) for q in PART_REMOVED], axis=0))
    if shape == "cone":
        # Shape::Cone, in the half-plane (rho, z) round its axis: the triangle (0, 0), (1, 0),
        # (0, 1), whose edge on the axis is no surface: the base z = 0 for rho <= 1 and the side
        # rho + z = 1.
        rho = np.hypot(p[:, 0], p[:, 1])
        z = p[:, 2]
        base = np.where(rho <= 1.0, np.abs(z), np.hypot(rho - 1.0, z))
        t = np.clip((1.0 - rho + z) / 2.0, 0.0, 1.0)
        side = np.hypot(rho - (1.0 - t), z - t)
        inside = (z > 0.0) & (rho + z < 1.0)
        return np.where(inside, -1.0, 1.0) * np.minimum(base, side)
    raise ValueError(shape)


def true_distance(shape: str, p: np.ndarray) -> np.ndarray:
    """Unsigned distance to the surface `pointform sample` draws from, or to the truth mesh of
    the bunny and the scanned meshes (see _signed_distance())."""
    mesh_path = _truth_mesh_path(shape)
    if mesh_path is not None:
        return _mesh_distance(mesh_path, p)
    return np.abs(_signed_distance(shape, p))


def true_normals(shape: str, p: np.ndarray, diag: float) -> np.ndarray:
    """The truth's outward unit normal nearest each point: a mesh truth's nearest triangle's; an
    analytic shape's the gradient of its signed distance (central differences of 10⁻⁴ of the
    diagonal; where the distance is not smooth, at the medial axis, any direction of it)."""
    mesh_path = _truth_mesh_path(shape)
    if mesh_path is not None:
        scene, normals = _mesh_truth(mesh_path)
        closest = scene.compute_closest_points(o3d.core.Tensor(p.astype(np.float32)))
        return normals[closest["primitive_ids"].numpy()]
    h = 1e-4 * diag
    gradient = np.stack([_signed_distance(shape, p + h * e) - _signed_distance(shape, p - h * e)
                         for e in np.eye(3)], 1)
    return gradient / np.maximum(np.linalg.norm(gradient, axis=1), 1e-300)[:, None]


def load_points(path: Path) -> np.ndarray:
    v = read_ply(str(path))
    return np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64)


def open3d_truth_to_mesh(mesh_path: Path, truth: np.ndarray) -> dict:
    """Open3D's own point-to-mesh distance (RaycastingScene) from the truth points: the
    cross-check of pointform distance."""
    loaded = o3d.io.read_triangle_mesh(str(mesh_path))
    mesh = o3d.geometry.TriangleMesh(loaded.vertices, loaded.triangles)
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    d = scene.compute_distance(o3d.core.Tensor(truth.astype(np.float32))).numpy()
    return {"o3d_truth_to_mesh_max": float(d.max()), "o3d_truth_to_mesh_mean": float(d.mean())}


def evaluate(shape, mesh_path: Path, truth: np.ndarray, samples: np.ndarray, diag: float,
             pointform: str, work: Path) -> dict:
    """Accuracy of a mesh against the analytic surface, `diag` the samples' diagonal:
    mesh -> truth exactly (analytic distance of 200k area-uniform mesh samples drawn with a
    fixed seed, for the means and the precision; for the maximum also of every vertex, edge
    midpoint and face centroid, so that one narrow spike or flap is not missed and the figure
    does not move from one evaluation of a mesh to the next), truth -> mesh exactly by
    `pointform distance` (point to triangle), with Open3D's RaycastingScene as a cross-check in
    a child process (Debian's Open3D aborts on an Eigen assertion inside it on some meshes: that
    costs the cross-check, not the row)."""
    loaded = o3d.io.read_triangle_mesh(str(mesh_path))
    if len(loaded.triangles) == 0:
        return {}
    # Geometry only: Debian's Open3D asserts on some zero vertex normals while sampling.
    mesh = o3d.geometry.TriangleMesh(loaded.vertices, loaded.triangles)
    area = mesh.get_surface_area()
    surface, surface_normals = surface_samples(mesh, 200000, np.random.default_rng(2026))
    mesh_to_truth = true_distance(shape, surface)
    # Inside-out pieces: the share of the area whose normal points away from the truth's
    # nearest outward normal (more than 90° apart).
    facing_away = float(np.mean(np.sum(surface_normals * true_normals(shape, surface, diag), 1)
                                < 0.0))
    corners = np.asarray(mesh.vertices)[np.asarray(mesh.triangles)]
    structure = np.concatenate([np.asarray(mesh.vertices), corners.mean(1),
                                0.5 * (corners + np.roll(corners, 1, axis=1)).reshape(-1, 3)])
    structure_max = float(true_distance(shape, structure).max())
    # pointform distance's thresholds are fractions of its own diagonal (truth and mesh).
    vertices = np.asarray(mesh.vertices)
    both = np.concatenate([truth, vertices])
    pf_diag = float(np.linalg.norm(both.max(0) - both.min(0)))
    taus = (0.005, 0.01)
    pf = run_measured([pointform, "distance", work / "truth.ply", mesh_path, "--json",
                       "--fscore", ",".join(f"{t * diag / pf_diag:.12g}" for t in taus)],
                      os.environ.copy(), 600, work / "distance")
    report = pf[3] or {}
    if "absolute" not in report:
        return {"evaluation": f"pointform distance failed ({pf[0]})"}
    truth_to_mesh = report["absolute"]["a_to_b"]
    # The tree keeps a reference into the cloud's points: the cloud must outlive it.
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(samples))
    tree = o3d.geometry.KDTreeFlann(cloud)
    spurious = 0
    for p in surface[::20]:
        _, _, d2 = tree.search_knn_vector_3d(p, 1)
        spurious += d2[0] > (0.01 * diag) ** 2
    out = {
        "hausdorff": max(mesh_to_truth.max(), structure_max, truth_to_mesh["max"]) / diag,
        "chamfer": (mesh_to_truth.mean() + truth_to_mesh["mean"]) / diag,
        "area": area,
        "spurious": spurious / len(surface[::20]),
        "facing_away": facing_away,
        "pf_truth_to_mesh_max": truth_to_mesh["max"],
        "pf_distance_s": pf[1],
    }
    for tau, score in zip(taus, report["fscore"]):
        precision = np.mean(mesh_to_truth < tau * diag)
        recall = score["recall"]
        out[f"f{tau}"] = 2 * precision * recall / max(precision + recall, 1e-12)
    out.update(isolated(open3d_truth_to_mesh, mesh_path, truth))
    return out


def _isolated_child(queue, function, args):
    queue.put(function(*args))


def isolated(function, *args) -> dict:
    """function(*args) in a child process: Debian's Open3D aborts on an internal assertion on
    some meshes, which must cost one measurement, not the run."""
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    child = context.Process(target=_isolated_child, args=(queue, function, args))
    child.start()
    child.join(timeout=1800)
    if child.is_alive():
        child.kill()
        return {"isolated": f"{function.__name__} timed out"}
    if child.exitcode != 0 or queue.empty():
        return {"isolated": f"{function.__name__} failed (exit {child.exitcode})"}
    return queue.get()


def evaluate_isolated(*args) -> dict:
    """evaluate() in a child process, so that an abort inside Open3D costs one row at most."""
    return isolated(evaluate, *args)


def main(argv=None) -> int:
    faulthandler.enable()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pointform", default="build/release/apps/pointform/pointform")
    ap.add_argument("--shapes", default="sphere,torus")
    ap.add_argument("--variants", default="clean,noisy+holes")
    ap.add_argument("--size", type=int, default=100000)
    ap.add_argument("--depths", default="8,9,10")
    ap.add_argument("--bpa", action="store_true", help="also ball pivoting (slow)")
    ap.add_argument("--mc-args", default="", help="extra arguments for pointform mc")
    ap.add_argument("--timeout", type=float, default=900)
    args = ap.parse_args(argv)
    env = os.environ.copy()
    rows = []
    with tempfile.TemporaryDirectory(prefix="pf-surface-") as tmp:
        work = Path(tmp)
        for shape in args.shapes.split(","):
            # The truth: exact samples of the analytic surface.
            truth_path = work / "truth.ply"
            run_measured([args.pointform, "sample", shape, "-n", "200000", "--seed", "99", "-o",
                          truth_path], env, 600, work / "truth")
            truth = load_points(truth_path)
            for variant in args.variants.split(","):
                raw = work / "raw.ply"
                surfels = work / "surfels.ply"
                run_measured([args.pointform, "sample", shape, "-n", str(args.size), "-o", raw,
                              *VARIANTS[variant]], env, 600, work / "sample")
                status, wall, _, rep = run_measured(
                    [args.pointform, "normals", raw, "-o", surfels, "--radius-scale", "1.5",
                     "--json"], env, 600, work / "normals")
                samples = load_points(surfels)
                diag = float(np.linalg.norm(samples.max(0) - samples.min(0)))
                tools = [("pointform mc", [args.pointform, "mc", surfels, "-o", work / "mc.ply",
                                           "--json", *args.mc_args.split()], work / "mc.ply")]
                for d in args.depths.split(","):
                    tools.append((f"Open3D Poisson {d}",
                                  ["/usr/bin/python3", HERE / "open3d_surface.py", surfels,
                                   work / f"poisson{d}.ply", "poisson", d], work / f"poisson{d}.ply"))
                if args.bpa:
                    tools.append(("Open3D ball pivoting",
                                  ["/usr/bin/python3", HERE / "open3d_surface.py", surfels,
                                   work / "bpa.ply", "bpa"], work / "bpa.ply"))
                for name, cmd, out in tools:
                    status, wall, peak, report = run_measured(cmd, env, args.timeout, work / "tool")
                    row = {"shape": shape, "variant": variant, "size": args.size, "tool": name,
                           "status": status, "wall_s": wall, "peak_mib": peak}
                    if report:
                        t = report.get("timings_s", {})
                        row["surface_s"] = (t.get("marching cubes", 0) + t.get("field", 0)) \
                            if "marching cubes" in t else t.get("surface")
                        row["vertices"] = report.get("vertices")
                        row.update(evaluate_isolated(shape, out, truth, samples, diag, args.pointform, work))
                    rows.append(row)
                    print(json.dumps(row), flush=True)
    print()
    header = ["shape", "variant", "tool", "surface s", "peak MiB", "vertices", "Hausdorff %diag",
              "Chamfer %diag", "F@0.5%", "F@1%", "spurious area", "pf/o3d max dist"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        if "chamfer" not in r:
            print(f"| {r['shape']} | {r['variant']} | {r['tool']} | {r['status']} |" + " |" * 8)
            continue
        check = (r["pf_truth_to_mesh_max"] or float("nan")) / max(
            r.get("o3d_truth_to_mesh_max", float("nan")), 1e-300)
        print(f"| {r['shape']} | {r['variant']} | {r['tool']} | {r['surface_s']:.2f} | "
              f"{r['peak_mib']:.0f} | {r['vertices']} | {100 * r['hausdorff']:.4g} | "
              f"{100 * r['chamfer']:.4f} | {r['f0.005']:.4f} | {r['f0.01']:.4f} | "
              f"{100 * r['spurious']:.2f}% | {'–' if math.isnan(check) else f'{check:.6f}'} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
