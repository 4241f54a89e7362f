#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Side-by-side benchmark of normal estimation + consistent orientation.

Runs pointform, Open3D and CGAL on the same generated point clouds (points only, same
order, same k) and prints, per input, the time of each stage, the peak resident memory,
the fraction of correctly oriented normals and the angular error, with ratios against
pointform. Run it with Debian's interpreter, which has numpy and python3-open3d:

    /usr/bin/python3 bench/peers/run_normals_bench.py --pointform build/apps/pointform/pointform \\
        --cgal build/bench/peers/cgal_normals --markdown bench/peers/RESULTS.md

See bench/peers/README.md for what is measured and how.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
sys.path.insert(0, str(HERE))
import plyio  # noqa: E402  (a sibling module, found through the line above)

TIME = "/usr/bin/time"
TOOLS = ("pointform", "open3d", "cgal")
PEERS = ("open3d", "cgal")
VARIANTS = {
    "clean": {"noise": 0.0, "holes": 0, "hole_radius": 0.0},
    "noisy+holes": {"noise": 0.002, "holes": 8, "hole_radius": 0.04},
}
SHAPES = ("sphere", "torus", "two-spheres", "plate", "cone")


# --------------------------------------------------------------------------------------------
# Inputs


@dataclass
class Input:
    """One benchmark input: points, exact outward normals and true surface components."""

    shape: str
    size: int  # requested sample count (before holes are cut)
    variant: str
    source: str  # "pointform sample" or "numpy fallback"
    points: np.ndarray  # N by 3, float32 or float64, as written to the tools' input files
    true_normals: np.ndarray  # N by 3, float64, unit length, outward
    labels: np.ndarray  # N, connected component of the sampled surface
    components: int
    diagonal: float
    ply_path: Path = field(default=Path())
    xyz_path: Path = field(default=Path())

    @property
    def name(self) -> str:
        return f"{self.shape} n={self.size} {self.variant}"


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _sample_sphere(rng, n, center=(0.0, 0.0, 0.0), radius=1.0):
    d = _unit(rng.normal(size=(n, 3)))
    return np.asarray(center) + radius * d, d


def _sample_torus(rng, n, major=1.0, minor=0.35):
    u_all, v_all = [], []
    while sum(len(u) for u in u_all) < n:  # rejection: area density is major + minor cos v
        m = 2 * n
        u = rng.uniform(0.0, 2.0 * np.pi, m)
        v = rng.uniform(0.0, 2.0 * np.pi, m)
        keep = rng.uniform(0.0, 1.0, m) < (major + minor * np.cos(v)) / (major + minor)
        u_all.append(u[keep])
        v_all.append(v[keep])
    u = np.concatenate(u_all)[:n]
    v = np.concatenate(v_all)[:n]
    ring = major + minor * np.cos(v)
    p = np.stack([ring * np.cos(u), ring * np.sin(u), minor * np.sin(v)], axis=1)
    nrm = np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)], axis=1)
    return p, nrm


def _sample_two_spheres(rng, n):
    p0, n0 = _sample_sphere(rng, n // 2, center=(-1.5, 0.0, 0.0))
    p1, n1 = _sample_sphere(rng, n - n // 2, center=(1.5, 0.0, 0.0))
    return np.concatenate([p0, p1]), np.concatenate([n0, n1])


def _sample_plate(rng, n, half=(1.0, 1.0, 0.05)):
    half = np.asarray(half)
    faces = [(axis, sign) for axis in range(3) for sign in (-1.0, 1.0)]
    areas = np.array([4.0 * np.prod(np.delete(half, axis)) for axis, _ in faces])
    face = rng.choice(len(faces), size=n, p=areas / areas.sum())
    p = rng.uniform(-1.0, 1.0, size=(n, 3)) * half
    nrm = np.zeros((n, 3))
    for f, (axis, sign) in enumerate(faces):
        on = face == f
        p[on, axis] = sign * half[axis]
        nrm[on, axis] = sign
    return p, nrm


def _sample_cone(rng, n):
    """Shape::Cone: radius 1, apex 1 above the base's centre (a 45° rim), area-uniform."""
    slant = np.sqrt(2.0)
    side = rng.uniform(0.0, slant + 1.0, n) < slant
    t = np.sqrt(rng.uniform(0.0, 1.0, n))
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    c, s = np.cos(angle), np.sin(angle)
    p = np.stack([t * c, t * s, np.where(side, 1.0 - t, 0.0)], axis=1)
    nrm = np.where(side[:, None], np.stack([c, s, np.ones(n)], axis=1) / slant,
                   np.array([0.0, 0.0, -1.0]))
    return p, nrm


def numpy_sample(shape, n, noise, holes, hole_radius, seed):
    """Fallback sampler with the semantics of `pointform sample` (used when it is absent)."""
    rng = np.random.default_rng(seed)
    sampler = {"sphere": _sample_sphere, "torus": _sample_torus,
               "two-spheres": _sample_two_spheres, "plate": _sample_plate,
               "cone": _sample_cone}[shape]
    p, nrm = sampler(rng, n)
    diag = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0)))
    if holes > 0:
        keep = np.ones(len(p), dtype=bool)
        for c in rng.choice(len(p), size=holes, replace=False):
            keep &= np.linalg.norm(p - p[c], axis=1) > hole_radius * diag
        p, nrm = p[keep], nrm[keep]
    if noise > 0.0:
        p = p + rng.normal(scale=noise * diag, size=p.shape)
    return p.astype(np.float32), nrm


def surface_components(points: np.ndarray) -> tuple[np.ndarray, int]:
    """Labels the connected pieces of the sampled surface (26-connected occupied voxels).

    The voxel size is 3x the mean sample spacing, estimated from the surface area that a
    coarse grid covers, so the sampled surface stays connected (holes do not split it)
    while pieces farther apart than about 3.5 voxels stay separate.
    """
    p = points.astype(np.float64)
    lo = p.min(axis=0)
    diag = float(np.linalg.norm(p.max(axis=0) - lo))
    coarse = diag / 64.0
    area = len(np.unique(np.floor((p - lo) / coarse).astype(np.int64), axis=0)) * coarse**2
    cell = max(3.0 * np.sqrt(area / len(p)), diag * 1e-3)
    ijk = np.floor((p - lo) / cell).astype(np.int64) + 1
    dims = ijk.max(axis=0) + 2
    code = (ijk[:, 0] * dims[1] + ijk[:, 1]) * dims[2] + ijk[:, 2]
    cells, inverse = np.unique(code, return_inverse=True)
    us, vs = [], []
    for dx in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dz in (-1, 0, 1):
                offset = (dx * dims[1] + dy) * dims[2] + dz
                if offset <= 0:
                    continue  # each of the 13 half-space offsets once
                pos = np.searchsorted(cells, cells + offset)
                pos = np.minimum(pos, len(cells) - 1)
                hit = cells[pos] == cells + offset
                us.append(np.nonzero(hit)[0])
                vs.append(pos[hit])
    u, v = np.concatenate(us), np.concatenate(vs)
    parent = np.arange(len(cells))
    while True:  # hook roots onto smaller roots, then jump pointers to the roots
        pu, pv = parent[u], parent[v]
        differ = pu != pv
        if not differ.any():
            break
        np.minimum.at(parent, np.maximum(pu, pv)[differ], np.minimum(pu, pv)[differ])
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    roots, labels = np.unique(parent[inverse], return_inverse=True)
    return labels, len(roots)


def make_input(shape, size, variant, seed, pointform, generator, work: Path, log) -> Input:
    spec = VARIANTS[variant]
    sample_path = work / "sample.ply"
    points = true_normals = None
    source = "numpy fallback"
    if generator in ("auto", "pointform") and pointform is not None:
        cmd = [str(pointform), "sample", shape, "-n", str(size), "--seed", str(seed),
               "-o", str(sample_path)]
        if spec["noise"] > 0.0:
            cmd += ["--noise", repr(spec["noise"])]
        if spec["holes"] > 0:
            cmd += ["--holes", str(spec["holes"]), "--hole-radius", repr(spec["hole_radius"])]
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=1800)
        if result.returncode == 0 and sample_path.exists():
            vertex = plyio.read_ply(sample_path)
            points, true_normals = plyio.positions(vertex), plyio.normals(vertex)
            if true_normals is None:
                raise SystemExit(f"{sample_path}: `pointform sample` wrote no normals")
            source = "pointform sample"
        elif generator == "pointform":
            raise SystemExit(f"`{' '.join(cmd)}` failed:\n{result.stderr.strip()}")
        else:
            log(f"  note: `pointform sample` failed ({result.stderr.strip()[:200]!r}); "
                "using the numpy sampler")
    if points is None:
        points, true_normals = numpy_sample(shape, size, seed=seed, **spec)

    true_normals = _unit(true_normals.astype(np.float64))
    labels, components = surface_components(points)
    diag = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    item = Input(shape, size, variant, source, points, true_normals, labels, components, diag)

    # Every tool reads exactly these coordinates: a points-only PLY (pointform, Open3D) and
    # the same values as text (CGAL); %.9g / %.17g round-trip float32 / float64 exactly.
    item.ply_path = work / "points.ply"
    item.xyz_path = work / "points.xyz"
    plyio.write_ply(item.ply_path, {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]},
                    comment=f"{item.name} ({source})")
    np.savetxt(item.xyz_path, points, fmt="%.9g" if points.dtype == np.float32 else "%.17g")
    return item


# --------------------------------------------------------------------------------------------
# Running the tools


@dataclass
class ToolRun:
    tool: str
    status: str = "ok"
    estimate_s: float | None = None
    orient_s: float | None = None
    wall_s: float | None = None
    peak_mib: float | None = None
    outward: float | None = None  # fraction with dot(n, n_true) > 0
    consistent: float | None = None  # same, up to one sign flip per true component
    angle_deg: float | None = None  # mean min(angle, 180 - angle) to the true normal
    unoriented: int | None = None
    report: dict | None = None
    note: str = ""

    @property
    def total_s(self) -> float | None:
        if self.estimate_s is None or self.orient_s is None:
            return None
        return self.estimate_s + self.orient_s


def run_measured(cmd, env, timeout, log_stem: Path):
    """Runs cmd under /usr/bin/time in its own process group; never outlives `timeout`."""
    time_path = log_stem.with_suffix(".time")
    full = [TIME, "-o", str(time_path), "-f", "%M %e", *map(str, cmd)]
    # Each run starts with no dirty pages of an earlier one (a 400 MB output of the run before can
    # slow this run's write several-fold while the kernel writes it back).
    os.sync()
    start = time.perf_counter()
    proc = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env, start_new_session=True)
    timed_out = False
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        timed_out = True
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
    except BaseException:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
        raise
    wall = time.perf_counter() - start
    log_stem.with_suffix(".stdout").write_text(out)
    log_stem.with_suffix(".stderr").write_text(err)

    lines = time_path.read_text().splitlines() if time_path.exists() else []
    peak_mib = None
    if lines and len(lines[-1].split()) == 2:
        peak_mib = int(lines[-1].split()[0]) / 1024.0
    if timed_out:
        return f"timeout (> {timeout:g} s)", wall, peak_mib, None
    if proc.returncode != 0:
        why = next((line for line in lines if line.startswith("Command")), "")
        if "signal 9" in why:
            status = "killed (SIGKILL, out of memory?)"
        elif "signal" in why:
            status = f"killed (signal {why.split()[-1]})"
        elif "out of memory" in err.lower() or "bad_alloc" in err:
            status = f"out of memory (exit {proc.returncode})"
        else:
            status = f"failed (exit {proc.returncode}): {err.strip()[-160:]}"
        return status, wall, peak_mib, None
    report = parse_report(out)
    if report is None:
        return "failed (no JSON report on stdout)", wall, peak_mib, None
    return "ok", wall, peak_mib, report


def parse_report(stdout: str) -> dict | None:
    """The last JSON object on stdout (one line or pretty-printed) that starts a line."""
    decoder = json.JSONDecoder()
    starts = [i for i in range(len(stdout)) if stdout[i] == "{" and
              (i == 0 or stdout[i - 1] == "\n")]
    for start in reversed(starts):
        try:
            report, _ = decoder.raw_decode(stdout, start)
        except json.JSONDecodeError:
            continue
        if isinstance(report, dict):
            return report
    return None


def evaluate(run: ToolRun, item: Input, output: Path) -> None:
    """Fills the quality figures of `run` from the tool's output PLY."""
    try:
        vertex = plyio.read_ply(output)
    except (OSError, plyio.PlyError) as error:
        run.status = f"bad output: {error}"
        return
    normals = plyio.normals(vertex)
    n = len(item.points)
    if normals is None or len(normals) != n:
        run.status = f"bad output: {0 if normals is None else len(normals)} normals for {n} points"
        return
    shift = np.abs(plyio.positions(vertex).astype(np.float64) - item.points).max()
    if shift > 1e-5 * item.diagonal:
        run.status = f"bad output: points reordered or moved (max shift {shift:.3g})"
        return
    length = np.linalg.norm(normals, axis=1)
    valid = np.isfinite(length) & (length > 0.0)
    dot = np.zeros(n)
    dot[valid] = np.einsum("ij,ij->i", normals[valid], item.true_normals[valid]) / length[valid]
    outward = valid & (dot > 0.0)
    run.outward = float(outward.mean())
    per_label = np.bincount(item.labels, weights=outward, minlength=item.components)
    sizes = np.bincount(item.labels, minlength=item.components)
    run.consistent = float(np.maximum(per_label, sizes - per_label).sum() / n)
    angle = np.degrees(np.arccos(np.clip(np.abs(dot), 0.0, 1.0)))  # invalid normals: 90°
    run.angle_deg = float(angle.mean())
    if int((~valid).sum()) > 0:
        run.note += f"{int((~valid).sum())} invalid normals; "


def run_tool(tool, exe, item, args, work: Path, env) -> ToolRun:
    output = work / f"{tool}_out.ply"
    if tool == "pointform":
        threads = ["--threads", args.threads] if args.pointform_threads_flag else []
        cmd = [exe, *threads, "normals", item.ply_path, "-o", output, "-k", args.k, "--json",
               *shlex.split(args.pointform_args)]
    elif tool == "open3d":
        cmd = [args.python, HERE / "open3d_normals.py", item.ply_path, output, "-k", args.k]
    else:
        cmd = [exe, item.xyz_path, output, "-k", args.k, "--threads", args.threads]

    best = None
    for attempt in range(args.repeat):
        output.unlink(missing_ok=True)
        run = ToolRun(tool)
        run.status, run.wall_s, run.peak_mib, report = run_measured(
            cmd, env, args.timeout, work / f"{tool}_{attempt}")
        run.report = report
        if run.status == "ok":
            t = report.get("timings_s", {})
            if tool == "pointform":
                run.estimate_s = _tree_s(t) + t.get("knn", 0.0) + t.get("normals", 0.0)
                run.orient_s = t.get("orientation")
                run.unoriented = report.get("unoriented")
            else:
                run.estimate_s, run.orient_s = t.get("estimate"), t.get("orient")
                run.unoriented = report.get("unoriented")
            reported = report.get("points")
            if run.total_s is None:
                run.status = "failed (report without stage timings)"
            elif reported is not None and reported != len(item.points):
                run.status = f"bad report: {reported} points for {len(item.points)}"
            else:
                evaluate(run, item, output)
        if best is None or (run.status == "ok" and (best.status != "ok"
                                                    or run.total_s < best.total_s)):
            best = run
        if run.status != "ok":
            break  # a timeout or an OOM will not get better on a second try
    if not args.keep_files:
        output.unlink(missing_ok=True)
    return best


# --------------------------------------------------------------------------------------------
# Reporting


def _fmt(value, spec) -> str:
    return "–" if value is None else format(value, spec)


def _tree_s(timings: dict) -> float:
    """pointform's index building: spatial sort + kd-tree build (reported apart from the kNN
    queries), 0 if absent."""
    return sum(timings.get(key, 0.0) for key in ("spatial sort", "kd-tree", "kd_tree", "kdtree"))


def _knn_ratios(timings: dict) -> str:
    orientation, knn = timings.get("orientation"), timings.get("knn")
    with_tree = None if knn is None else knn + _tree_s(timings)
    return (f"{_fmt(_ratio(orientation, knn), '.2f')}x the kNN queries, "
            f"{_fmt(_ratio(orientation, with_tree), '.2f')}x sort + kd-tree + kNN")


def _percent(fraction):
    return None if fraction is None else 100.0 * fraction


def _ratio(a, b):
    return None if a is None or b is None or b <= 0.0 else a / b


COLUMNS = ["tool", "estimate s", "orient s", "total s", "wall s", "peak MiB", "outward %",
           "consistent %", "angle err °", "unoriented", "total/pf", "peak/pf"]


def table_rows(runs: list[ToolRun]) -> list[list[str]]:
    pf = next((r for r in runs if r.tool == "pointform" and r.status == "ok"), None)
    rows = []
    for r in runs:
        ok = r.status == "ok"
        rows.append([
            r.tool,
            _fmt(r.estimate_s, ".3f"), _fmt(r.orient_s, ".3f"), _fmt(r.total_s, ".3f"),
            _fmt(r.wall_s, ".2f"), _fmt(r.peak_mib, ".0f"),
            _fmt(_percent(r.outward), ".2f"), _fmt(_percent(r.consistent), ".2f"),
            _fmt(r.angle_deg, ".2f"), _fmt(r.unoriented, "d"),
            _fmt(_ratio(r.total_s, pf.total_s) if (pf and ok) else None, ".2f"),
            _fmt(_ratio(r.peak_mib, pf.peak_mib) if (pf and ok) else None, ".2f"),
        ])
    return rows


def print_table(item: Input, runs: list[ToolRun], out=sys.stdout) -> None:
    print(f"\n== {item.shape}, n={item.size}, {item.variant}: {len(item.points)} points, "
          f"{item.components} component(s), input from {item.source}", file=out)
    rows = table_rows(runs)
    widths = [max(len(c), *(len(row[i]) for row in rows)) for i, c in enumerate(COLUMNS)]
    print("  ".join(c.rjust(w) if i else c.ljust(w) for i, (c, w) in
                    enumerate(zip(COLUMNS, widths))), file=out)
    for row, run in zip(rows, runs):
        line = "  ".join(v.rjust(w) if i else v.ljust(w) for i, (v, w) in
                         enumerate(zip(row, widths)))
        status = "" if run.status == "ok" else f"  [{run.status}]"
        print(line + status + (f"  ({run.note.rstrip('; ')})" if run.note else ""), file=out)
    pf = next((r for r in runs if r.tool == "pointform" and r.report), None)
    if pf:
        t = pf.report.get("timings_s", {})
        print(f"   pointform: sort + kd-tree {_tree_s(t):.3f} s, kNN {t.get('knn', 0):.3f} s, "
              f"normals {t.get('normals', 0):.3f} s, orientation {t.get('orientation', 0):.3f} s "
              f"({_knn_ratios(t)}), "
              f"radius {t.get('radius', 0):.3f} s, read {t.get('read', 0):.3f} s, "
              f"write {t.get('write', 0):.3f} s; components {pf.report.get('components')}, "
              f"flipped {pf.report.get('flipped')}", file=out)


def summary_lines(results) -> list[str]:
    """The headline figures: orientation vs kNN, speed and memory ratios at the largest size."""
    lines = []
    for item, runs in results:
        pf = next((r for r in runs if r.tool == "pointform" and r.status == "ok"), None)
        if pf and pf.report:
            t = pf.report.get("timings_s", {})
            lines.append(f"pointform orientation vs kNN, {item.name}: orientation "
                         f"{t.get('orientation', 0):.3f} s = {_knn_ratios(t)}")
    largest = max((item.size for item, _ in results), default=0)
    for item, runs in results:
        if item.size != largest:
            continue
        pf = next((r for r in runs if r.tool == "pointform" and r.status == "ok"), None)
        peers = [r for r in runs if r.tool in PEERS and r.status == "ok"]
        failed = [f"{r.tool}: {r.status}" for r in runs if r.tool in PEERS and r.status != "ok"]
        if pf is None or not peers:
            continue
        fastest = min(peers, key=lambda r: r.total_s)
        leanest = min(peers, key=lambda r: r.peak_mib or float("inf"))
        speed = _fmt(_ratio(fastest.total_s, pf.total_s), ".2f")
        memory = _fmt(_ratio(pf.peak_mib, leanest.peak_mib), ".2f")
        lines.append(
            f"{item.name}: fastest peer {fastest.tool} {fastest.total_s:.3f} s vs pointform "
            f"{pf.total_s:.3f} s -> pointform {speed}x as fast; leanest peer {leanest.tool} "
            f"{_fmt(leanest.peak_mib, '.0f')} MiB vs pointform {_fmt(pf.peak_mib, '.0f')} MiB "
            f"-> pointform peak {memory}x"
            + (f" (not finished: {'; '.join(failed)})" if failed else ""))
    return lines


def markdown(results, environment: list[str], summary: list[str]) -> str:
    head = ["input", "points"] + COLUMNS
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for item, runs in results:
        for row, run in zip(table_rows(runs), runs):
            if run.status != "ok":
                row[0] += f" ({run.status})"
            out.append("| " + " | ".join([item.name, str(len(item.points))]
                                         + row) + " |")
    text = ["# Normal estimation + orientation: pointform vs Open3D vs CGAL", ""]
    text += [f"- {line}" for line in environment] + [""]
    text += out + [""]
    text += ["total = estimate + orient (pointform: kNN + normals + orientation), in seconds; "
             "wall = the whole process (start-up, I/O); peak = max RSS; outward = share of "
             "normals with dot(n, n_true) > 0; consistent = the same up to one sign per "
             "true surface component; angle err = mean unoriented angle to the true normal.",
             ""]
    text += [f"- {line}" for line in summary]
    return "\n".join(text) + "\n"


# --------------------------------------------------------------------------------------------


def find_executable(given, candidates, what):
    if given:
        path = Path(given)
        if not (path.is_file() and os.access(path, os.X_OK)):
            raise SystemExit(f"--{what}: '{given}' is not an executable file")
        return path.resolve()
    for path in candidates:
        if path.is_file() and os.access(path, os.X_OK):
            return path.resolve()
    return None


def tool_version(cmd) -> str:
    try:
        result = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
        return (result.stdout or result.stderr).strip().splitlines()[-1]
    except (OSError, subprocess.TimeoutExpired, IndexError):
        return "?"


def tool_help(cmd) -> str:
    """The --help text of cmd (a path or a list: executable + subcommand)."""
    cmd = [cmd] if isinstance(cmd, (str, Path)) else cmd
    try:
        result = subprocess.run([*cmd, "--help"], capture_output=True, text=True, timeout=120)
        return result.stdout + result.stderr
    except (OSError, subprocess.TimeoutExpired):
        return ""


def environment_lines(args, exes, env) -> list[str]:
    cpu = "?"
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in
                   Path("/proc/cpuinfo").read_text().splitlines() if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    lines = [f"machine: {cpu}, {os.cpu_count()} logical CPUs, {mem_gib:.0f} GiB RAM; "
             f"{args.threads} thread(s) per tool (OMP_NUM_THREADS); k = {args.k}; "
             f"best of {args.repeat} run(s)"]
    if exes.get("pointform"):
        pf = exes["pointform"]
        extra = f" {args.pointform_args}" if args.pointform_args else ""
        lines.append(f"pointform: {pf} ({tool_version([pf, '--version'])}), "
                     f"`pointform normals -k {args.k}{extra}`")
        if "--graph-k" in tool_help([pf, "normals"]) and "--graph-k" not in extra:
            lines.append("pointform's orientation graph uses its default --graph-k (see "
                         "`pointform normals --help`), the peers' use k; "
                         f"--pointform-args \"--graph-k {args.k}\" gives all the same graph k")
    if exes.get("open3d"):
        base = subprocess.run([TIME, "-f", "%M", args.python, "-c", "import numpy, open3d"],
                              capture_output=True, text=True, env=env)
        baseline = base.stderr.strip().splitlines()[-1] if base.stderr.strip() else "?"
        version = tool_version([args.python, "-c", "import open3d; print(open3d.__version__)"])
        mib = f"{int(baseline) / 1024:.0f} MiB" if baseline.isdigit() else "?"
        lines.append(f"Open3D {version} ({args.python}); its peak includes the Python "
                     f"interpreter + `import open3d` baseline of {mib}")
    if exes.get("cgal"):
        lines.append(f"CGAL: {exes['cgal']} (pca_estimate_normals + mst_orient_normals; "
                     "concurrency reported per run below)")
    return lines


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pointform", help="pointform CLI (default: build/apps/pointform/"
                        "pointform under the current directory, the repository or its parent)")
    parser.add_argument("--pointform-args", default="", help="extra arguments for `pointform "
                        "normals`, e.g. \"--graph-k 16\" (default: none)")
    parser.add_argument("--cgal", help="cgal_normals peer (default: build*/bench/peers/"
                        "cgal_normals under the same places)")
    parser.add_argument("--python", default="/usr/bin/python3",
                        help="interpreter with python3-open3d (default: %(default)s)")
    parser.add_argument("--tools", default=",".join(TOOLS), help="default: %(default)s")
    parser.add_argument("--sizes", default="100000,1000000", help="default: %(default)s")
    parser.add_argument("--shapes", default="sphere,torus,two-spheres",
                        help=f"any of {','.join(SHAPES)} (default: %(default)s)")
    parser.add_argument("--variants", default=",".join(VARIANTS),
                        help="clean: exact samples; noisy+holes: Gaussian noise 0.002 of the "
                        "bbox diagonal, 8 holes of radius 0.04 (default: %(default)s)")
    parser.add_argument("--k", type=int, default=16, help="neighbours, all tools and stages "
                        "(default: %(default)s)")
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1,
                        help="threads per tool (default: all, %(default)s)")
    parser.add_argument("--timeout", type=float, default=900.0,
                        help="seconds per tool run (default: %(default)s)")
    parser.add_argument("--repeat", type=int, default=1,
                        help="runs per tool and input; the fastest counts (default: 1)")
    parser.add_argument("--seed", type=int, default=1, help="sampling seed (default: 1)")
    parser.add_argument("--generator", choices=("auto", "pointform", "numpy"), default="auto",
                        help="input sampler: `pointform sample` when present (auto), or numpy")
    parser.add_argument("--out-dir", default="/tmp/pointform-normals-bench",
                        help="inputs, outputs, logs and results.json (default: %(default)s)")
    parser.add_argument("--markdown", help="also write the results as a markdown file")
    parser.add_argument("--keep-files", action="store_true",
                        help="keep the generated inputs and the tools' output PLY files")
    args = parser.parse_args(argv)
    args.sizes = [int(s) for s in args.sizes.split(",") if s]
    args.shapes = [s for s in args.shapes.split(",") if s]
    args.variants = [v for v in args.variants.split(",") if v]
    args.tools = [t for t in args.tools.split(",") if t]
    for values, allowed, what in ((args.shapes, SHAPES, "shape"), (args.variants, VARIANTS,
                                  "variant"), (args.tools, TOOLS, "tool")):
        bad = [v for v in values if v not in allowed]
        if bad:
            parser.error(f"unknown {what} {bad}; choose from {list(allowed)}")
    if args.k < 2 or args.threads < 1 or args.repeat < 1 or not args.sizes:
        parser.error("need k >= 2, threads >= 1, repeat >= 1 and at least one size")
    return args


def main(argv=None) -> int:
    args = parse_args(argv)
    out_dir = Path(args.out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)

    def log(message):
        print(message, flush=True)

    places = [Path.cwd(), REPO, REPO.parent]
    pointform = find_executable(args.pointform, [p / "build/apps/pointform/pointform"
                                                 for p in places], "pointform")
    cgal = find_executable(args.cgal, [p / b / "bench/peers/cgal_normals" for p in places
                                       for b in ("build", "build-bench")], "cgal")
    # OMP_NUM_THREADS sets the threads of all tools; pointform also gets its own option.
    args.pointform_threads_flag = pointform is not None and "--threads" in tool_help(pointform)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["OMP_NUM_THREADS"] = str(args.threads)
    have_open3d = subprocess.run([args.python, "-c", "import open3d"], env=env,
                                 capture_output=True).returncode == 0
    exes = {"pointform": pointform, "cgal": cgal, "open3d": args.python if have_open3d else None}
    tools = []
    for tool in args.tools:
        if exes[tool] is None:
            why = f"no open3d in {args.python}" if tool == "open3d" else "not built"
            log(f"note: {tool} is not available ({why}); skipped")
        else:
            tools.append(tool)
    if not tools:
        raise SystemExit("no tool to run")

    environment = environment_lines(args, {t: exes[t] for t in tools}, env)
    for line in environment:
        log(line)

    results = []
    records = []
    for shape in args.shapes:
        for size in args.sizes:
            for variant in args.variants:
                work = out_dir / f"{shape}_{size}_{variant.replace('+', '_')}"
                work.mkdir(parents=True, exist_ok=True)
                item = make_input(shape, size, variant, args.seed, pointform, args.generator,
                                  work, log)
                runs = []
                for tool in tools:
                    log(f"[{item.name}] {tool} ...")
                    runs.append(run_tool(tool, exes[tool], item, args, work, env))
                if not args.keep_files:
                    item.ply_path.unlink(missing_ok=True)
                    item.xyz_path.unlink(missing_ok=True)
                    (work / "sample.ply").unlink(missing_ok=True)
                print_table(item, runs)
                results.append((item, runs))
                records.append({
                    "shape": shape, "size": size, "variant": variant, "source": item.source,
                    "points": len(item.points), "components": item.components,
                    "runs": [{k: v for k, v in vars(r).items()} | {"total_s": r.total_s}
                             for r in runs],
                })
                (out_dir / "results.json").write_text(json.dumps(
                    {"environment": environment, "inputs": records}, indent=1))

    summary = summary_lines(results)
    print("\n== summary")
    for line in summary:
        print(f"- {line}")
    cgal_modes = {r.report.get("concurrency") for _, runs in results for r in runs
                  if r.tool == "cgal" and r.report}
    if cgal_modes:
        print(f"- CGAL concurrency: {', '.join(sorted(cgal_modes))}")
        summary.append(f"CGAL concurrency: {', '.join(sorted(cgal_modes))}")
    if args.markdown:
        Path(args.markdown).write_text(markdown(results, environment, summary))
        print(f"\nmarkdown table written to {args.markdown}")
    print(f"results.json and logs in {out_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
