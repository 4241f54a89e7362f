#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Multiresolution editing benchmark (GitHub issue 16, item 7): pointform against CGAL.

Two parts, in one run:

1. Edit. One edit of a hierarchy at level j (default J - 2): region = a ball around the handle
   (the level-j vertex nearest the highest point of the finest level along --up, the bunny's
   ear tip), radius --roi-fraction of the bounding-box diagonal; the handle is translated by
   --move-fraction of the diagonal along --direction, at the scales --scales (the targets).
   pointform (bench/peers/multires_deform edit): MultiresDeformer, a bi-Laplacian on level j
   factored once, finer levels re-synthesized from their details. CGAL (bench/peers/cgal_deform):
   Surface_mesh_deformation with SRE_ARAP on the finest level at rest, region = the finest
   vertices in the same ball, handles = the finest vertices with the level-j handle's id (ids are
   shared across levels) plus the finest vertices of the region within half the mean level-j edge
   length of it, the same translations. Measured: precomputation (pointform: the deformer's
   construction; CGAL: construction + region + preprocess()), time per edit after it (pointform:
   apply(); CGAL: reset() + targets + deform() with its default 5 iterations and tolerance 1e-4),
   best of R per target and averaged over the targets, peak memory of each process
   (/usr/bin/time), and how each keeps the fine relief: for every finest vertex of the region,
   the rotation R of its 1-ring (orthogonal Procrustes between its rest and deformed edge vectors)
   and the angle between its deformed normal and R times its rest normal (area-weighted vertex
   normals), after the last (largest) target.

2. Resynthesis. DetailSynthesizer::synthesize(mesh, details, 0) of every level above the base after
   a smooth non-rigid map of the base, on hierarchies of about 100k and 1M vertices, 1 and 2
   threads, best of R: vertices re-synthesized per second.

Inputs are made with `pointform reconstruct` from the Stanford bunny (bun_zipper.ply) unless
given: levels 4 and 5 with as many base faces as give the vertex count asked for
(--sizes), predictor midpoint (and butterfly with --predictors midpoint,butterfly). Files go to
--out-dir (default /tmp/pf-deform-bench), never into the repository.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from plyio import read_mesh_ply  # noqa: E402  (a sibling module, found through the line above)
REPO = HERE.parent.parent

# ---------------------------------------------------------------------------------------------
# Tools and processes


def find_tool(given: str | None, names: list[str]) -> Path | None:
    if given:
        p = Path(given)
        return p if p.is_file() else None
    roots = [Path.cwd(), REPO, REPO.parent]
    for root in roots:
        for name in names:
            for p in sorted(root.glob(name)):
                if p.is_file() and os.access(p, os.X_OK):
                    return p
    return None


def run(cmd: list[str], log_prefix: Path, timeout: float) -> dict:
    """Runs cmd under /usr/bin/time; returns its JSON stdout plus peak_mib, wall_s and the
    1-minute load average before and after (other processes on the machine skew the timings)."""
    load_before = os.getloadavg()[0]
    time_file = log_prefix.with_suffix(".time")
    full = ["/usr/bin/time", "-f", "%M %e", "-o", str(time_file)] + [str(c) for c in cmd]
    print("  $ " + " ".join(shlex.quote(str(c)) for c in cmd), flush=True)
    try:
        proc = subprocess.run(full, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:.0f} s"}
    log_prefix.with_suffix(".stdout").write_text(proc.stdout)
    log_prefix.with_suffix(".stderr").write_text(proc.stderr)
    if proc.returncode != 0:
        return {"error": f"exit {proc.returncode}: {proc.stderr.strip()[-400:]}"}
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    kib, wall = time_file.read_text().split()[-2:]
    out["peak_mib"] = int(kib) / 1024.0
    out["wall_s"] = float(wall)
    out["load"] = [round(load_before, 2), round(os.getloadavg()[0], 2)]
    return out


# ---------------------------------------------------------------------------------------------
# Inputs


def make_hierarchy(pointform: Path, source: Path, levels: int, vertices: int, predictor: str,
                   out_dir: Path, timeout: float) -> Path:
    """A hierarchy of about `vertices` vertices: levels J with F0 = 2 V / 4^J base faces."""
    base_faces = max(200, round(2 * vertices / 4 ** levels))
    name = f"bunny_L{levels}_F{base_faces}_{predictor}"
    pfh = out_dir / f"{name}.pfh"
    if not pfh.exists():
        cmd = [pointform, "reconstruct", source, "-o", out_dir / f"{name}.ply",
               "--levels", str(levels), "--base-faces", str(base_faces),
               "--predictor", predictor, "--save-hierarchy", pfh, "--json"]
        print("  $ " + " ".join(shlex.quote(str(c)) for c in cmd), flush=True)
        subprocess.run([str(c) for c in cmd], check=True, timeout=timeout,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return pfh


# ---------------------------------------------------------------------------------------------
# Meshes and the relief measure


def vertex_normals(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = x[faces[:, 0]], x[faces[:, 1]], x[faces[:, 2]]
    fn = np.cross(b - a, c - a)  # area-weighted
    n = np.zeros_like(x)
    for k in range(3):
        np.add.at(n, faces[:, k], fn)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def procrustes_rotations(cov: np.ndarray) -> np.ndarray:
    """argmin_R sum |R e_rest - e_def|^2 for each S = sum e_rest e_def^T."""
    u, _, vt = np.linalg.svd(cov)
    v = np.transpose(vt, (0, 2, 1))
    ut = np.transpose(u, (0, 2, 1))
    det = np.linalg.det(v @ ut)
    fix = np.ones((len(cov), 3))
    fix[:, 2] = np.sign(np.where(det == 0, 1.0, det))
    return (v * fix[:, None, :]) @ ut


def normal_angles(rot: np.ndarray, n0: np.ndarray, n1: np.ndarray) -> np.ndarray:
    predicted = np.einsum("nij,nj->ni", rot, n0)
    return np.degrees(np.arccos(np.clip(np.sum(predicted * n1, axis=1), -1.0, 1.0)))


def relief_measure(rest: np.ndarray, deformed: np.ndarray, faces: np.ndarray,
                   roi: np.ndarray, moving_threshold: float, rings: int) -> dict:
    """Angle between the deformed normal and R × the rest normal, R the 1-ring's Procrustes
    rotation; plus the edge-length change in the region and motion outside it."""
    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    in_roi = np.zeros(len(rest), dtype=bool)
    in_roi[roi] = True
    e0 = rest[edges[:, 1]] - rest[edges[:, 0]]
    e1 = deformed[edges[:, 1]] - deformed[edges[:, 0]]
    # S_i = sum over the 1-ring of e_rest e_def^T (the same outer product from either end).
    outer = e0[:, :, None] * e1[:, None, :]
    cov = np.zeros((len(rest), 3, 3))
    np.add.at(cov, edges[:, 0], outer)
    np.add.at(cov, edges[:, 1], outer)
    n0 = vertex_normals(rest, faces)[roi]
    n1 = vertex_normals(deformed, faces)[roi]
    angle = normal_angles(procrustes_rotations(cov[roi]), n0, n1)
    # The same with the rotation of a wider patch: the 1-ring covariances summed over `rings`
    # rings (each round adds every neighbour's sum), the scale of a level-j edge. The 1-ring's
    # own rotation follows its normal closely whatever happens; this one asks whether the fine
    # normals turn with the surface around them.
    wide = cov.reshape(len(rest), 9)
    for _ in range(rings):
        grown = wide.copy()
        for a, b in ((0, 1), (1, 0)):
            for c in range(9):
                grown[:, c] += np.bincount(edges[:, a], weights=wide[edges[:, b], c],
                                           minlength=len(rest))
        wide = grown
    wide_angle = normal_angles(procrustes_rotations(wide.reshape(-1, 3, 3)[roi]), n0, n1)
    # The part of the region that really moves (most of a ball region barely does).
    moving = np.linalg.norm(deformed[roi] - rest[roi], axis=1) > moving_threshold
    moving_angle = angle[moving] if moving.any() else np.zeros(1)
    moving_wide = wide_angle[moving] if moving.any() else np.zeros(1)
    edge_in = in_roi[edges[:, 0]] & in_roi[edges[:, 1]]
    l0 = np.linalg.norm(e0[edge_in], axis=1)
    l1 = np.linalg.norm(e1[edge_in], axis=1)
    ok = l0 > 0
    stretch = np.abs(l1[ok] / l0[ok] - 1.0)
    outside = ~in_roi
    moved_outside = float(np.max(np.linalg.norm(deformed[outside] - rest[outside], axis=1))) \
        if outside.any() else 0.0
    return {
        "angle_mean_deg": float(angle.mean()),
        "angle_median_deg": float(np.median(angle)),
        "angle_p95_deg": float(np.percentile(angle, 95)),
        "angle_max_deg": float(angle.max()),
        "moving_vertices": int(moving.sum()),
        "moving_angle_mean_deg": float(moving_angle.mean()),
        "moving_angle_p95_deg": float(np.percentile(moving_angle, 95)),
        "rings": rings,
        "wide_angle_mean_deg": float(wide_angle.mean()),
        "wide_angle_p95_deg": float(np.percentile(wide_angle, 95)),
        "wide_moving_angle_mean_deg": float(moving_wide.mean()),
        "edge_stretch_mean": float(stretch.mean()),
        "edge_stretch_p95": float(np.percentile(stretch, 95)),
        "max_move_outside_roi": moved_outside,
        "roi_vertices": int(len(roi)),
    }


# ---------------------------------------------------------------------------------------------
# The edit


def edit_benchmark(args, tools, pfh: Path, label: str, work: Path) -> dict:
    md = tools["multires_deform"]
    out: dict = {"input": str(pfh), "label": label}
    # The edit is placed on the finest level at rest: the reconstruction's output beside the .pfh.
    rest_ply = pfh.with_suffix(".ply")
    x, _ = read_mesh_ply(rest_ply)
    lo, hi = x.min(axis=0), x.max(axis=0)
    diagonal = float(np.linalg.norm(hi - lo))
    up = np.array([float(c) for c in args.up.split(",")])
    top = x[int(np.argmax(x @ up))]
    direction = np.array([float(c) for c in args.direction.split(",")])
    direction /= np.linalg.norm(direction)
    translation = args.move_fraction * diagonal * direction
    radius = args.roi_fraction * diagonal
    levels = json.loads(subprocess.run(
        [str(md), "resynthesis", str(pfh), "--repeat", "1", "--threads", "1"],
        capture_output=True, text=True, check=True).stdout)["levels"]
    level = args.edit_level if args.edit_level >= 0 else max(0, levels - 1 - 2)
    out.update({"diagonal": diagonal, "level": level, "center": top.tolist(), "radius": radius,
                "translation": translation.tolist()})
    common = ["--level", str(level), "--center", *map(repr, top.tolist()),
              "--radius", repr(radius), "--handle-point", *map(repr, top.tolist()),
              "--translate", *map(repr, translation.tolist()), "--scales", args.scales,
              "--repeat", str(args.repeat)]
    out["pointform"] = {}
    for threads in args.edit_threads:
        prefix = work / f"{label}_pf_t{threads}"
        out["pointform"][threads] = run(
            [md, "edit", pfh, *common, "--out", prefix, "--threads", str(threads)],
            prefix, args.timeout)
    pf_prefix = work / f"{label}_pf_t{args.edit_threads[-1]}"
    pf = out["pointform"][args.edit_threads[-1]]
    if "error" in pf:
        return out
    rest, faces = read_mesh_ply(Path(f"{pf_prefix}_rest.ply"))
    roi = np.loadtxt(f"{pf_prefix}_roi.txt", dtype=np.int64, ndmin=1)
    pf_def, _ = read_mesh_ply(Path(f"{pf_prefix}_deformed.ply"))
    # "Moving": displaced by more than a tenth of the largest translation.
    threshold = 0.1 * float(np.linalg.norm(translation)) * float(args.scales.split(",")[-1])
    # A level-j edge spans 2^(J - j) edges of the finest level.
    rings = 2 ** (levels - 1 - level)
    out["pointform_relief"] = relief_measure(rest, pf_def, faces, roi, threshold, rings)
    if tools.get("cgal"):
        prefix = work / f"{label}_cgal"
        cg = run([tools["cgal"], f"{pf_prefix}_rest.ply", f"{pf_prefix}_roi.txt",
                  f"{pf_prefix}_handles.txt", f"{pf_prefix}_targets.txt",
                  f"{prefix}_deformed.ply", "--repeat", str(args.cgal_repeat)],
                 prefix, args.timeout)
        out["cgal"] = cg
        if "error" not in cg:
            cg_def, cg_faces = read_mesh_ply(Path(f"{prefix}_deformed.ply"))
            if cg_faces.shape != faces.shape or np.any(np.sort(cg_faces, axis=1).sum(1) !=
                                                       np.sort(faces, axis=1).sum(1)):
                out["cgal_note"] = "CGAL's output faces differ from the input's"
            out["cgal_relief"] = relief_measure(rest, cg_def, faces, roi, threshold, rings)
            handles = np.loadtxt(f"{pf_prefix}_handles.txt", dtype=np.int64, ndmin=1)
            last = translation * float(args.scales.split(",")[-1])
            diff = np.linalg.norm(pf_def[roi] - cg_def[roi], axis=1)
            out["pf_vs_cgal"] = {
                "rms_over_translation": float(np.sqrt(np.mean(diff ** 2)) /
                                              np.linalg.norm(translation)),
                "max_over_translation": float(diff.max() / np.linalg.norm(translation)),
                "pf_handle_error": float(np.max(np.linalg.norm(
                    pf_def[handles] - rest[handles] - last, axis=1))),
                "cgal_handle_error": float(np.max(np.linalg.norm(
                    cg_def[handles] - rest[handles] - last, axis=1))),
            }
    return out


# ---------------------------------------------------------------------------------------------
# Report


def fmt_s(seconds: float) -> str:
    if seconds >= 1.0:
        return f"{seconds:.2f} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds * 1e6:.0f} µs"


def markdown(results: dict) -> str:
    lines = ["# Multiresolution editing: pointform against CGAL", ""]
    env = results["environment"]
    lines.append(f"Run {env['date']} on {env['machine']} ({env['cpus']} logical CPUs, load "
                 f"average {env['load_before']} before the run), `{env['command']}`.")
    lines.append("")
    lines.append("## Edit: time per edit after precomputation")
    lines.append("")
    lines.append("| hierarchy | level j (vertices) | finest vertices | finest region | tool | "
                 "threads | precompute | per edit | CGAL / pointform | peak MiB | load before / "
                 "after |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|")
    for e in results["edits"]:
        cg = e.get("cgal", {})
        for threads, pf in e["pointform"].items():
            if "error" in pf:
                lines.append(f"| {e['label']} | | | | pointform | {threads} | {pf['error']} |"
                             " | | | |")
                continue
            ratio = (f"{cg['edit_mean_s'] / pf['apply_mean_s']:.0f}×"
                     if cg and "error" not in cg else "")
            lines.append(
                f"| {e['label']} | {e['level']} ({pf['level_vertices']:,}) | "
                f"{pf['vertices']:,} | {pf['finest_roi_vertices']:,} | pointform | {threads} | "
                f"{fmt_s(pf['precompute_s'])} | {fmt_s(pf['apply_mean_s'])} | {ratio} | "
                f"{pf['peak_mib']:.0f} | {pf['load'][0]:.2f} / {pf['load'][1]:.2f} |")
        if cg and "error" not in cg:
            lines.append(
                f"| {e['label']} | | {cg['vertices']:,} | {cg['roi_vertices']:,} | CGAL SRE_ARAP "
                f"| 1 | {fmt_s(cg['setup_s'] + cg['preprocess_s'])} (preprocess "
                f"{fmt_s(cg['preprocess_s'])}) | {fmt_s(cg['edit_mean_s'])} | | "
                f"{cg['peak_mib']:.0f} | {cg['load'][0]:.2f} / {cg['load'][1]:.2f} |")
        elif cg:
            lines.append(f"| {e['label']} | | | | CGAL | 1 | {cg['error']} | | | | |")
    lines.append("")
    lines.append("Per target (scale of the translation: pointform apply() at the most threads / "
                 "CGAL reset + deform):")
    lines.append("")
    for e in results["edits"]:
        pf = list(e["pointform"].values())[-1]
        cg = e.get("cgal", {})
        if "error" in pf:
            continue
        scales = results["arguments"]["scales"].split(",")
        parts = []
        for i, s in enumerate(scales):
            text = f"{s}: {fmt_s(pf['apply_s'][i])}"
            if cg and "error" not in cg:
                text += f" / {fmt_s(cg['edit_s'][i])}"
            parts.append(text)
        lines.append(f"- {e['label']}: " + "; ".join(parts))
    lines.append("")
    lines.append("## Edit: how the fine relief is kept (after the largest target)")
    lines.append("")
    lines.append("Angle between each region vertex's deformed normal and its rest normal turned "
                 "by the rotation of its 1-ring (orthogonal Procrustes of the rest and deformed "
                 "edge vectors), area-weighted vertex normals; lower is better. *Moving*: the "
                 "region's vertices displaced by more than a tenth of the translation. Edge "
                 "stretch: |deformed / rest length − 1| over the region's edges (the edit "
                 "stretches the region, so this is not zero for either tool). Largest move "
                 "outside region: world units; pointform's region is a ball of level j, so the "
                 "finer vertices just outside it whose stencil reads a moved vertex of level j "
                 "move too. *Wide*: the same angle with the rotation of a wider patch (the 1-ring "
                 "covariances summed over as many rings as a level-j edge spans at the finest "
                 "level, 2^(J − j)): the 1-ring's own rotation follows its normal closely "
                 "whatever the deformation (a 1.5 × stretch of one axis of the whole bunny gives "
                 "0.10° mean), the wide one asks whether the fine normals turn with the "
                 "surface around them.")
    lines.append("")
    lines.append("| hierarchy | tool | mean ° | median ° | p95 ° | max ° | moving vertices | "
                 "moving mean ° | moving p95 ° | edge stretch mean | edge stretch p95 | "
                 "largest move outside region | wide rings | wide mean ° | wide p95 ° | "
                 "wide moving mean ° |")
    lines.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for e in results["edits"]:
        for tool, key in (("pointform", "pointform_relief"), ("CGAL SRE_ARAP", "cgal_relief")):
            r = e.get(key)
            if not r:
                continue
            lines.append(
                f"| {e['label']} | {tool} | {r['angle_mean_deg']:.2f} | "
                f"{r['angle_median_deg']:.2f} | {r['angle_p95_deg']:.2f} | "
                f"{r['angle_max_deg']:.1f} | {r['moving_vertices']:,} | "
                f"{r['moving_angle_mean_deg']:.2f} | {r['moving_angle_p95_deg']:.2f} | "
                f"{r['edge_stretch_mean']:.4f} | "
                f"{r['edge_stretch_p95']:.4f} | {r['max_move_outside_roi']:.2e} | "
                f"{r['rings']} | {r['wide_angle_mean_deg']:.2f} | {r['wide_angle_p95_deg']:.2f} | "
                f"{r['wide_moving_angle_mean_deg']:.2f} |")
    lines.append("")
    for e in results["edits"]:
        pf = list(e["pointform"].values())[-1]
        if "error" in pf:
            continue
        text = (f"- {e['label']}: level {e['level']}, ball of radius {e['radius']:.4g} "
                f"({results['arguments']['roi_fraction']} × diagonal {e['diagonal']:.4g}) "
                f"around the handle, translation {results['arguments']['move_fraction']} × "
                f"diagonal = {np.linalg.norm(e['translation']):.4g}; pointform: "
                f"{pf['handle_vertices']} handle vertex of level {e['level']} (id "
                f"{pf['handles'][0]}), {pf['region_vertices']:,} region vertices of level "
                f"{e['level']} ({pf['free_vertices']:,} free); CGAL: "
                f"{pf['finest_handle_vertices']} finest handle vertices (within "
                f"{pf['handle_radius']:.3g} of it)")
        if "pf_vs_cgal" in e:
            d = e["pf_vs_cgal"]
            text += (f"; the two results differ by {d['rms_over_translation']:.3f} (RMS) and "
                     f"{d['max_over_translation']:.3f} (max) of the translation over the region; "
                     f"largest handle error {d['pf_handle_error']:.2e} (pointform, finest handles "
                     f"beside the level-j one follow by synthesis) and "
                     f"{d['cgal_handle_error']:.2e} (CGAL)")
        lines.append(text + ".")
    lines.append("")
    lines.append("## Resynthesis of every level above the base")
    lines.append("")
    lines.append("| hierarchy | predictor | vertices | re-synthesized | threads | best time | "
                 "vertices / s | round trip error | load before / after |")
    lines.append("|---|---|---|---|---|---|---|---|---|")
    for r in results["resynthesis"]:
        if "error" in r:
            lines.append(f"| {r['label']} | | | | | {r['error']} | | |")
            continue
        for run_ in r["runs"]:
            lines.append(
                f"| {r['label']} | {r['predictor']} | {r['vertices']:,} | "
                f"{r['resynthesized']:,} | {run_['threads']} | {fmt_s(run_['best_s'])} | "
                f"{run_['vertices_per_s'] / 1e6:.1f} M | {r['round_trip_max_error']:.1e} | "
                f"{r['load'][0]:.2f} / {r['load'][1]:.2f} |")
    lines.append("")
    lines.append("## Summary")
    lines.append("")
    lines.extend(f"- {s}" for s in results["summary"])
    lines.append("")
    return "\n".join(lines)


def summarize(results: dict, args) -> list[str]:
    out = []
    for e in results["edits"]:
        cg = e.get("cgal", {})
        for threads, pf in e["pointform"].items():
            if "error" in pf or not cg or "error" in cg:
                continue
            ratio = cg["edit_mean_s"] / pf["apply_mean_s"]
            verdict = "meets" if ratio >= 20 else "MISSES"
            out.append(f"{e['label']}, pointform at {threads} thread(s): "
                       f"{fmt_s(pf['apply_mean_s'])} per edit against CGAL's "
                       f"{fmt_s(cg['edit_mean_s'])}: {ratio:.0f}× faster ({verdict} the ≥ 20× "
                       f"target); precomputation {fmt_s(pf['precompute_s'])} against "
                       f"{fmt_s(cg['setup_s'] + cg['preprocess_s'])}.")
        if "pointform_relief" in e and "cgal_relief" in e:
            out.append(f"{e['label']}: mean relief angle {e['pointform_relief']['angle_mean_deg']:.2f}° "
                       f"(pointform) against {e['cgal_relief']['angle_mean_deg']:.2f}° (CGAL).")
    for r in results["resynthesis"]:
        if "error" in r:
            continue
        for run_ in r["runs"]:
            if run_["threads"] == 2:
                rate = run_["vertices_per_s"]
                verdict = "meets" if rate >= 10e6 else "MISSES"
                out.append(f"Resynthesis {r['label']} ({r['predictor']}), 2 threads: "
                           f"{rate / 1e6:.1f} M vertices/s ({verdict} the ≥ 10 M/s target).")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pointform", help="pointform CLI (to make the inputs)")
    ap.add_argument("--multires-deform", help="bench/peers/multires_deform")
    ap.add_argument("--cgal", help="bench/peers/cgal_deform")
    ap.add_argument("--source", default=str(REPO.parent / "shared/data/stanford-bunny/"
                                                         "reconstruction/bun_zipper.ply"),
                    help="points the hierarchies are reconstructed from")
    ap.add_argument("--sizes", default="100000,1000000",
                    help="vertex counts of the generated hierarchies (levels 4 and 5)")
    ap.add_argument("--predictors", default="midpoint",
                    help="predictors of the resynthesis hierarchies (midpoint,butterfly)")
    ap.add_argument("--inputs", help="comma-separated .pfh files instead of generated ones "
                                     "(each needs its finest level as NAME.ply beside it)")
    ap.add_argument("--edit-sizes", default="100000,1000000",
                    help="which of --sizes (midpoint) get the edit benchmark")
    ap.add_argument("--edit-level", type=int, default=-1, help="level j (default J - 2)")
    ap.add_argument("--up", default="0,1,0", help="the handle is the highest vertex along this")
    ap.add_argument("--direction", default="1,0,0", help="direction of the translation")
    ap.add_argument("--roi-fraction", type=float, default=0.3,
                    help="region radius, fraction of the bounding-box diagonal")
    ap.add_argument("--move-fraction", type=float, default=0.1,
                    help="translation length, fraction of the diagonal")
    ap.add_argument("--scales", default="0.25,0.5,0.75,1", help="targets: translation scales")
    ap.add_argument("--edit-threads", default="1,2", help="pointform threads for the edit")
    ap.add_argument("--repeat", type=int, default=10, help="pointform: best of R")
    ap.add_argument("--cgal-repeat", type=int, default=3, help="CGAL: best of R per target")
    ap.add_argument("--timeout", type=float, default=1800)
    ap.add_argument("--out-dir", default="/tmp/pf-deform-bench")
    ap.add_argument("--markdown", help="write the tables here (e.g. bench/peers/RESULTS_deform.md)")
    args = ap.parse_args()
    args.edit_threads = [int(t) for t in args.edit_threads.split(",")]

    out_dir = Path(args.out_dir)
    work = out_dir / "runs"
    work.mkdir(parents=True, exist_ok=True)
    tools = {
        "pointform": find_tool(args.pointform, ["build/release/apps/pointform/pointform",
                                                "build*/apps/pointform/pointform"]),
        "multires_deform": find_tool(args.multires_deform, ["build-bench/bench/peers/multires_deform",
                                                            "build*/bench/peers/multires_deform"]),
        "cgal": find_tool(args.cgal, ["build-bench/bench/peers/cgal_deform",
                                      "build*/bench/peers/cgal_deform"]),
    }
    for name, path in tools.items():
        print(f"{name}: {path or 'not found'}")
    if not tools["multires_deform"]:
        print("multires_deform not found (build the bench targets)", file=sys.stderr)
        return 2
    if not tools["cgal"]:
        print("note: cgal_deform not found, the CGAL peer is skipped", file=sys.stderr)

    # Inputs.
    hierarchies = []  # (label, predictor, size, path)
    if args.inputs:
        for p in args.inputs.split(","):
            hierarchies.append((Path(p).stem, "?", None, Path(p)))
    else:
        if not tools["pointform"]:
            print("the pointform CLI is needed to make the inputs (--pointform)", file=sys.stderr)
            return 2
        sizes = [int(s) for s in args.sizes.split(",")]
        for predictor in args.predictors.split(","):
            for i, size in enumerate(sizes):
                levels = 4 + i if len(sizes) <= 2 else 4
                pfh = make_hierarchy(tools["pointform"], Path(args.source), levels, size,
                                     predictor, out_dir, args.timeout)
                hierarchies.append((f"bunny L{levels} ~{size // 1000}k", predictor, size, pfh))
    edit_sizes = {int(s) for s in args.edit_sizes.split(",") if s}

    results = {
        "environment": {
            "date": time.strftime("%Y-%m-%d %H:%M"),
            "machine": f"{platform.machine()} {platform.processor() or ''}".strip(),
            "cpus": os.cpu_count(),
            "load_before": " ".join(f"{x:.2f}" for x in os.getloadavg()),
            "command": " ".join(shlex.quote(a) for a in sys.argv),
        },
        "arguments": {k: v for k, v in vars(args).items()},
        "tools": {k: str(v) if v else None for k, v in tools.items()},
        "edits": [],
        "resynthesis": [],
    }

    for label, predictor, size, pfh in hierarchies:
        if predictor in ("midpoint", "?") and (size is None or size in edit_sizes):
            print(f"edit: {label}", flush=True)
            results["edits"].append(edit_benchmark(args, tools, pfh, label.replace(" ", "_")
                                                   .replace("~", ""), work))
            results["edits"][-1]["label"] = label
    for label, predictor, size, pfh in hierarchies:
        print(f"resynthesis: {label} ({predictor})", flush=True)
        r = run([tools["multires_deform"], "resynthesis", pfh, "--repeat", str(args.repeat),
                 "--threads", "1,2"], work / f"resynthesis_{pfh.stem}", args.timeout)
        r["label"] = label
        results["resynthesis"].append(r)

    results["summary"] = summarize(results, args)
    (out_dir / "results.json").write_text(json.dumps(results, indent=2, default=str))
    text = markdown(results)
    print()
    print(text)
    if args.markdown:
        Path(args.markdown).write_text(text)
        print(f"wrote {args.markdown}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
