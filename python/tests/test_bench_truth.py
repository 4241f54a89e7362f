# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""The benchmark's truth (bench/peers/run_surface_bench.py): the outward normals that its
"facing away" column (the share of a mesh's area turned inside out) measures against."""

import os
import sys

import numpy as np
import pytest

from conftest import ROOT, run_cli

sys.path.insert(0, os.path.join(ROOT, "bench", "peers"))


@pytest.mark.parametrize("shape", ["sphere", "torus", "blobby", "part", "plate", "cone"])
def test_analytic_truth_normals_are_the_samples_exact_normals(shape, tmp_path):
    pytest.importorskip("open3d")
    from plyio import read_ply
    from run_surface_bench import _signed_distance, true_normals

    path = tmp_path / "samples.ply"
    run_cli("sample", shape, "-n", 20000, "--seed", 3, "-o", path)
    v = read_ply(str(path))
    points = np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64)
    exact = np.stack([v["nx"], v["ny"], v["nz"]], 1).astype(np.float64)
    diag = float(np.linalg.norm(points.max(0) - points.min(0)))
    dots = np.sum(true_normals(shape, points, diag) * exact, 1)
    # Within 10⁻⁴ of the diagonal of a crease or a thin plate's rim the difference quotient sees
    # both faces: a few samples in 20,000 at most.
    assert np.mean(dots > 0.999) > 0.995
    assert np.all(dots > 0.0)
    # The samples lie on the surface the signed distance measures (float positions), and a
    # step of 10⁻³ along their normals leaves them that far outside (within the rounding and
    # where a crease or rim is nearer than the step).
    assert np.max(np.abs(_signed_distance(shape, points))) < 1e-5 * diag
    step = 1e-3 * diag
    outside = _signed_distance(shape, points + step * exact)
    assert np.mean(np.abs(outside - step) < 1e-2 * step) > 0.99


def test_mesh_truth_normals_and_an_inside_out_copy():
    o3d = pytest.importorskip("open3d")
    from run_surface_bench import SCANNED_MESHES, true_normals
    from virtual_scan import surface_samples

    mesh = o3d.io.read_triangle_mesh(str(SCANNED_MESHES["fandisk"]))
    points, normals = surface_samples(mesh, 20000, np.random.default_rng(5))
    diag = float(np.linalg.norm(points.max(0) - points.min(0)))
    truth = true_normals("fandisk", points, diag)
    # The truth's own area samples: their faces' normals, but where a sample lies on an edge
    # (the nearest triangle is then either).
    assert np.mean(np.sum(truth * normals, 1) > 0.999) > 0.99
    # Turned inside out, every sample faces away from it.
    assert np.mean(np.sum(truth * -normals, 1) < 0.0) > 0.99
