# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""distance: the figures of `pointform distance --json`, and geometric truth."""

import numpy as np
import pytest

import pointform
from conftest import BUNNY_SCAN, BUNNY_SMALL, run_cli, sphere_points

RUN_REPORT = ("timings_s", "threads", "parallel", "peak_rss_bytes")


def test_distance_is_the_cli_json():
    cli = run_cli("distance", BUNNY_SCAN, BUNNY_SMALL, "--samples", 20000, "--seed", 3,
                  "--fscore", "0.005,0.01", "--json", json_output=True)
    for key in RUN_REPORT:
        cli.pop(key)
    ours = pointform.distance(BUNNY_SCAN, BUNNY_SMALL, samples=20000, seed=3, fscore=[0.005, 0.01])
    assert ours == cli


def test_distance_of_objects_equals_that_of_their_files():
    by_path = pointform.distance(BUNNY_SCAN, BUNNY_SMALL, samples=5000)
    by_object = pointform.distance(pointform.read(BUNNY_SCAN), pointform.read_mesh(BUNNY_SMALL),
                                   samples=5000)
    for side in ("a", "b"):
        assert by_object[side]["file"] is None
        by_object[side]["file"] = by_path[side]["file"]
    assert by_object == by_path


def test_distance_between_concentric_spheres():
    inner = pointform.PointCloud(sphere_points(4000, radius=1.0))
    outer = pointform.PointCloud(sphere_points(4000, radius=1.1, seed=11))
    result = pointform.distance(inner, outer)
    assert result["a"]["kind"] == "points" and result["a"]["samples"] == 4000
    hausdorff = result["absolute"]["hausdorff"]
    # Nearest-point distances: at least the 0.1 gap, at most the gap plus the sample spacing.
    assert 0.1 <= result["absolute"]["a_to_b"]["min"] and hausdorff < 0.1 + 0.06
    assert result["relative_to_diagonal"]["hausdorff"] == pytest.approx(hausdorff / result["diagonal"])


def test_bad_distance_input(tmp_path):
    with pytest.raises(pointform.InvalidInput, match="expected a path, PointCloud or Mesh"):
        pointform.distance(np.zeros((3, 3)), BUNNY_SMALL)
    with pytest.raises(pointform.IoError, match="does not exist"):
        pointform.distance(tmp_path / "missing.ply", BUNNY_SMALL)
    with pytest.raises(ValueError, match="samples"):
        pointform.distance(BUNNY_SMALL, BUNNY_SMALL, samples=0)
    with pytest.raises(ValueError, match="F-score|threshold|fscore"):
        pointform.distance(BUNNY_SMALL, BUNNY_SMALL, fscore=[-1.0])
    flat = pointform.Mesh(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError, match="zero area"):
        pointform.distance(flat, BUNNY_SMALL)
