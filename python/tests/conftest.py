# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Shared fixtures: the repository's paths, the CLI built beside the module, small inputs."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)  # the pointform/ shim, as `import pointform` from the root finds it

import pointform  # noqa: E402

BUILD = os.environ.get("POINTFORM_BUILD", os.path.join(ROOT, "build", "release"))
CLI = os.path.join(BUILD, "apps", "pointform", "pointform")
BUNNY_SCAN = os.path.join(ROOT, "data", "bunny", "bun_zipper.ply")
BUNNY_SMALL = os.path.join(ROOT, "data", "bunny", "bun_zipper_res4.ply")
SPOT = os.path.join(ROOT, "data", "meshes", "spot.obj")


def run_cli(*args, json_output=False):
    """Runs the CLI; returns its parsed JSON (json_output) or its completed process."""
    if not os.path.exists(CLI):
        pytest.skip(f"the CLI is not built ({CLI})")
    command = [CLI, *map(str, args)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    assert done.returncode == 0, f"{command} failed: {done.stderr}"
    return json.loads(done.stdout) if json_output else done


def sphere_points(n, radius=1.0, seed=7):
    """n points on a sphere (a Fibonacci lattice, slightly jittered), float64."""
    rng = np.random.default_rng(seed)
    i = np.arange(n) + 0.5
    phi = np.arccos(1.0 - 2.0 * i / n)
    theta = np.pi * (1.0 + 5.0**0.5) * i + rng.uniform(-0.1, 0.1, n)
    p = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)
    return radius * p


@pytest.fixture(scope="session")
def sphere_cloud():
    return pointform.PointCloud(sphere_points(2000).astype(np.float32))


@pytest.fixture(scope="session")
def sphere_surfels(sphere_cloud):
    surfels, _ = pointform.surfels(sphere_cloud)
    return surfels


@pytest.fixture(scope="session")
def bunny_points():
    return pointform.read_points(BUNNY_SCAN)
