# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Side-by-side benchmark of the whole reconstruction, from raw points, in one run:
pointform reconstruct (semi-regular, §5) against pointform mc at the same vertex count (the
paper's Fig. 4 claim), Open3D's Poisson at depth 9 and, with --bpa, ball pivoting.

Every tool starts from the same raw points (an analytic shape sampled by `pointform sample`,
clean or with 0.2% noise and holes; the shipped bunny scan; or simulated multi-view range scans
of a mesh of data/meshes/ (fandisk, a CAD part; spot, a smooth cow; teapot, with a thin spout
and a handle) or of a machined part written in the modeling language (bracket, flange, finblock:
run_surface_bench.CAD_PARTS) by virtual_scan.py: occlusion, grazing dropout, range noise, holes
and strays, measured against the mesh) and estimates its own normals: pointform inside its
commands, Open3D with estimate_normals + orient_normals_consistent_tangent_plane (k = 16), so
times are end to end. Per tool: wall time, peak memory (/usr/bin/time), vertices, accuracy
against the true analytic surface (symmetric Hausdorff and Chamfer in % of the diagonal,
F-score at 0.5% and 1%; see run_surface_bench.py), the share of triangles with a minimum angle
under 20°, and the share of interior vertices of valence 6.

Run with /usr/bin/python3 (Debian's python3-open3d):
  /usr/bin/python3 bench/peers/run_reconstruct_bench.py --pointform build/release/apps/pointform/pointform
"""

from __future__ import annotations

import argparse
import faulthandler
import hashlib
import json
import math
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import open3d as o3d

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run_normals_bench import run_measured  # noqa: E402
from plyio import write_ply  # noqa: E402
from run_surface_bench import (BUNNY_MESH, SCANNED_MESHES, VARIANTS, ensure_cad_part,  # noqa: E402
                               evaluate_isolated, load_points, sample_args)
from virtual_scan import scan, surface_samples  # noqa: E402

HERE = Path(__file__).resolve().parent


def mesh_quality(path: Path) -> dict:
    """Minimum-angle distribution and valence-6 share of a triangle mesh."""
    mesh = o3d.io.read_triangle_mesh(str(path))
    v = np.asarray(mesh.vertices)
    f = np.asarray(mesh.triangles)
    if len(f) == 0:
        return {}
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]

    def angle(p, q, r):
        u, w = q - p, r - p
        cos = np.einsum("ij,ij->i", u, w) / np.maximum(
            np.linalg.norm(u, axis=1) * np.linalg.norm(w, axis=1), 1e-300)
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))

    min_angle = np.minimum(np.minimum(angle(a, b, c), angle(b, c, a)), angle(c, a, b))
    # Valence over interior vertices: a vertex is on the boundary if one of its edges has one face.
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    boundary = np.zeros(len(v), bool)
    boundary[unique[counts == 1].ravel()] = True
    valence = np.bincount(unique.ravel(), minlength=len(v))
    used = valence > 0
    interior = used & ~boundary
    return {
        "vertices": int(np.count_nonzero(np.bincount(f.ravel(), minlength=len(v)))),
        "faces": int(len(f)),
        "min_angle_under_20": float(np.mean(min_angle < 20.0)),
        "min_angle_p1": float(np.percentile(min_angle, 1)),
        "valence6": float(np.mean(valence[interior] == 6)) if interior.any() else float("nan"),
    }


def write_points(path: Path, points: np.ndarray) -> None:
    """Positions only, as binary float32 PLY."""
    write_ply(str(path), {"x": points[:, 0].astype(np.float32), "y": points[:, 1].astype(np.float32),
                          "z": points[:, 2].astype(np.float32)})


def thread_scaling(args) -> int:
    """Normals and reconstruct of one clean blobby at 1, 2, ... threads: wall time and peak."""
    env = os.environ.copy()
    cores = os.cpu_count() or 1
    counts = sorted({t for t in (1, 2, 4, 8, 16, cores) if t <= cores})
    with tempfile.TemporaryDirectory(prefix="pf-scaling-") as tmp:
        work = Path(tmp)
        run_measured([args.pointform, "sample", "blobby", "-n", str(args.scaling), "-o",
                      work / "with_normals.ply"], env, args.timeout, work / "sample")
        raw = work / "raw.ply"
        write_points(raw, load_points(work / "with_normals.ply"))
        print("| command | samples | threads | wall s | peak MiB | bytes per sample | result | "
              "same bytes as 1 thread | stages s |")
        print("|---|---|---|---|---|---|---|---|---|")
        ratios = []
        for command in args.commands.split(","):
            first = None
            for threads in counts:
                out = work / f"{command}_{threads}.ply"
                status, wall, peak, report = run_measured(
                    [args.pointform, "-j", str(threads), command, raw, "-o", out, "--json"], env,
                    args.timeout, work / "run")
                result = ""
                if report and command == "reconstruct":
                    result = f"level {report.get('finest_level')}, {report.get('vertices')} vertices"
                per_sample = peak * 1048576 / args.scaling if peak else float("nan")
                digest = hashlib.sha256(out.read_bytes()).hexdigest() if out.exists() else None
                first = first or digest
                stages = (report or {}).get("timings_s") or {}
                stage_text = ", ".join(f"{k} {v:.1f}" for k, v in
                                       (stages.items() if isinstance(stages, dict) else stages))
                print(f"| {command} | {args.scaling} | {threads} | {wall:.1f} | {peak or 0:.0f} | "
                      f"{per_sample:.0f} | {status if status != 'ok' else result} | "
                      f"{'yes' if digest and digest == first else 'NO'} | {stage_text} |",
                      flush=True)
                if command == "normals" and isinstance(stages, dict) and stages.get("knn"):
                    knn = stages["knn"]
                    ratios.append(f"`normals` at {threads} thread(s): {stages['total'] / knn:.2f}x "
                                  f"its kNN queries in process ({stages['total']:.1f} s against "
                                  f"{knn:.1f}), {wall / knn:.2f}x as a whole process")
        for line in ratios:
            print(f"\n{line}", flush=True)
    return 0


def main(argv=None) -> int:
    faulthandler.enable()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pointform", default="build/release/apps/pointform/pointform")
    ap.add_argument("--shapes", default="sphere,torus,blobby,part,plate,bunny,fandisk",
                    help="analytic shapes of `pointform sample`, thin-plate (its plate 0.02 "
                         "thick), bunny (the shipped scan, "
                         "clean only, against the Stanford reconstruction bun_zipper), and "
                         "fandisk, spot or teapot (simulated scans of data/meshes/, against the mesh: "
                         "--scan-seeds; --size and --variants do not apply) and bracket, flange or "
                         "finblock (machined parts built by `pointform model`, scanned the same way)")
    ap.add_argument("--sample-seed", type=int, default=1,
                    help="seed of `pointform sample` for the analytic shapes' raw points (a held-out "
                         "draw of the same shapes; the truth's samples keep their own seed)")
    ap.add_argument("--scan-seeds", default="1,2,3",
                    help="seeds of virtual_scan.py for each scanned mesh, comma-separated")
    ap.add_argument("--variants", default="clean,noisy+holes")
    ap.add_argument("--size", type=int, default=100000)
    ap.add_argument("--bpa", action="store_true", help="also ball pivoting (slow)")
    ap.add_argument("--reconstruct-args", default="", help="extra arguments for pointform reconstruct")
    ap.add_argument("--mc-args", default="",
                    help="extra arguments for every pointform mc run (e.g. \"--fill-holes 0\" "
                         "beside a reconstruct that keeps the holes)")
    ap.add_argument("--matched-levels", type=int, default=3,
                    help="levels of the semi-regular mesh that marching cubes is also matched "
                         "against, 0 = none "
                         "(the automatic stop can end at a mesh coarser than any marching cubes "
                         "of the field: its cells would be larger than the influence radii)")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--no-poisson", action="store_true", help="skip Open3D Poisson (slow)")
    ap.add_argument("--commands", default="normals,reconstruct",
                    help="with --scaling: the commands to time, comma-separated")
    ap.add_argument("--scaling", type=int, default=0, metavar="N",
                    help="only the thread-scaling table: normals and reconstruct of a clean "
                         "blobby of N samples at 1, 2, ... threads (up to the cores)")
    args = ap.parse_args(argv)
    if args.scaling:
        return thread_scaling(args)
    env = os.environ.copy()
    rows = []
    with tempfile.TemporaryDirectory(prefix="pf-reconstruct-") as tmp:
        work = Path(tmp)
        for shape in args.shapes.split(","):
            truth_path = work / "truth.ply"
            if shape == "bunny":
                # The truth is the Stanford reconstruction; the samples are its own vertices.
                write_points(truth_path, load_points(BUNNY_MESH))
            elif shape in SCANNED_MESHES:
                ensure_cad_part(shape, args.pointform)
                # The truth's points (for recall): area-uniform samples of the mesh.
                truth_mesh = o3d.io.read_triangle_mesh(str(SCANNED_MESHES[shape]))
                write_points(truth_path,
                             surface_samples(truth_mesh, 200000, np.random.default_rng(99))[0])
            else:
                run_measured([args.pointform, "sample", *sample_args(shape), "-n", "200000",
                              "--seed", "99", "-o", truth_path], env, 600, work / "truth")
            truth = load_points(truth_path)
            variants = (args.variants.split(",") if shape not in SCANNED_MESHES else
                        [f"scan {seed}" for seed in args.scan_seeds.split(",")])
            for variant in variants:
                raw = work / "raw.ply"
                if shape == "bunny":
                    if variant != "clean":
                        continue
                    write_points(raw, load_points(BUNNY_MESH))
                elif shape in SCANNED_MESHES:
                    write_points(raw, scan(str(SCANNED_MESHES[shape]), int(variant.split()[1])))
                else:
                    run_measured([args.pointform, "sample", *sample_args(shape), "-n",
                                  str(args.size), "--seed", str(args.sample_seed), "-o",
                                  work / "with_normals.ply", *VARIANTS[variant]], env, 600,
                                 work / "sample")
                    # Raw points: no tool may see the true normals.
                    write_points(raw, load_points(work / "with_normals.ply"))
                samples = load_points(raw)
                diag = float(np.linalg.norm(samples.max(0) - samples.min(0)))

                def measure(name, cmd, out):
                    status, wall, peak, report = run_measured(cmd, env, args.timeout, work / "tool")
                    row = {"shape": shape, "variant": variant,
                           "size": len(samples) if shape in SCANNED_MESHES else args.size, "tool": name,
                           "status": status, "wall_s": wall, "peak_mib": peak}
                    levels = (report or {}).get("levels") or []
                    if levels and "folded_faces" in levels[-1]:
                        # Child faces turned against their parent (§5.2.2) left in the output.
                        row["folded_faces"] = levels[-1]["folded_faces"]
                    if status == "ok" and out.exists():
                        row.update(mesh_quality(out))
                        row.update(evaluate_isolated(shape, out, truth, samples, diag,
                                                     args.pointform, work))
                    if report and "cell" in report:
                        row["cell"] = report["cell"]
                    rows.append(row)
                    print(json.dumps(row), flush=True)
                    return row

                measure("pointform reconstruct",
                        [args.pointform, "reconstruct", raw, "-o", work / "semi.ply", "--json",
                         *args.reconstruct_args.split()], work / "semi.ply")
                if args.matched_levels > 0:
                    measure(f"pointform reconstruct --levels {args.matched_levels}",
                            [args.pointform, "reconstruct", raw, "-o", work / "semi_j.ply",
                             "--json", "--levels", str(args.matched_levels),
                             *args.reconstruct_args.split()], work / "semi_j.ply")
                default_mc = measure("pointform mc (default cell)",
                                     [args.pointform, "mc", raw, "-o", work / "mc_default.ply",
                                      "--json", *args.mc_args.split()], work / "mc_default.ply")
                # Marching cubes at the vertex counts of the default mesh (the paper's Fig. 4
                # claim at the default) and of the --levels one. Vertices grow with the square of
                # the resolution: from the default cell's mesh (fine enough to be defined
                # everywhere) an estimate, then probes correct it (coarser cells than
                # the influence radii cut a mesh short).
                side = float((samples.max(0) - samples.min(0)).max())
                matched = [("the default's", work / "semi.ply")]
                if args.matched_levels > 0:
                    matched.append((f"--levels {args.matched_levels}'s", work / "semi_j.ply"))
                for label, mesh_path in matched:
                    target = o3d.io.read_triangle_mesh(str(mesh_path)).vertices
                    if not (len(target) and default_mc.get("vertices") and default_mc.get("cell")):
                        continue
                    resolution = max(8, round(side / default_mc["cell"] *
                                              math.sqrt(len(target) / default_mc["vertices"])))
                    # Probes until the count is within 3% (at most eight), the square law's step
                    # kept inside the resolutions that gave too few and too many (else halved):
                    # a thin plate's mesh does not follow the law where its cells near its
                    # thickness (a 1M clean plate: 80k vertices at 195 cells, 21k at 140, for
                    # a target of 41k).
                    few, many = 8, None
                    for _ in range(8):
                        probe = run_measured([args.pointform, "mc", raw, "-o", work / "probe.ply",
                                              "--json", "--resolution", str(resolution),
                                              *args.mc_args.split()], env,
                                             args.timeout, work / "probe")[3] or {}
                        if not probe.get("vertices"):
                            break
                        ratio = len(target) / probe["vertices"]
                        if abs(ratio - 1.0) <= 0.03:
                            break
                        if ratio > 1.0:
                            few = max(few, resolution)
                        else:
                            many = resolution if many is None else min(many, resolution)
                        step = max(8, round(resolution * math.sqrt(ratio)))
                        if step <= few or (many is not None and step >= many):
                            step = (few + many) // 2 if many is not None else 2 * few
                        if step == resolution:
                            break
                        resolution = step
                    measure(f"pointform mc at {label} vertex count (resolution {resolution})",
                            [args.pointform, "mc", raw, "-o", work / "mc.ply", "--json",
                             "--resolution", str(resolution), *args.mc_args.split()],
                            work / "mc.ply")
                if args.no_poisson:
                    continue
                measure("Open3D Poisson 9",
                        ["/usr/bin/python3", HERE / "open3d_surface.py", raw, work / "poisson9.ply",
                         "poisson", "9", "--estimate-normals", "16"], work / "poisson9.ply")
                if args.bpa:
                    measure("Open3D ball pivoting",
                            ["/usr/bin/python3", HERE / "open3d_surface.py", raw, work / "bpa.ply",
                             "bpa", "--estimate-normals", "16"], work / "bpa.ply")
    print()
    header = ["shape", "variant", "tool", "wall s", "peak MiB", "vertices", "Hausdorff %diag",
              "Chamfer %diag", "F@0.5%", "F@1%", "min angle < 20°", "valence 6", "folds", "facing away"]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for r in rows:
        if "chamfer" not in r:
            print(f"| {r['shape']} | {r['variant']} | {r['tool']} | {r['status']} |" + " |" * 10)
            continue
        vertices = r.get("vertices") or ""
        print(f"| {r['shape']} | {r['variant']} | {r['tool']} | {r['wall_s']:.1f} | "
              f"{r['peak_mib']:.0f} | {vertices} | {100 * r['hausdorff']:.4g} | "
              f"{100 * r['chamfer']:.4f} | {r['f0.005']:.4f} | {r['f0.01']:.4f} | "
              f"{100 * r['min_angle_under_20']:.2f}% | {100 * r['valence6']:.1f}% | "
              f"{r.get('folded_faces', '')} | {100 * r.get('facing_away', math.nan):.2f}% |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
