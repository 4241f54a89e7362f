# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Field and scene: signed distances checked against the analytic sphere."""

import numpy as np
import pytest

import pointform
from conftest import sphere_points


def radial_queries(radii, n=200):
    directions = sphere_points(n, seed=3)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return np.concatenate([r * directions for r in radii]), directions


def test_point_field_of_a_sphere_is_its_signed_distance(sphere_surfels):
    field = pointform.Field(sphere_surfels, fit="quadric")
    points, directions = radial_queries([0.95, 1.0, 1.05])
    values, gradients = field.evaluate(points)
    assert values.shape == (600,) and gradients.shape == (600, 3)
    expected = np.linalg.norm(points, axis=1) - 1.0
    # 2000 samples of the unit sphere (spacing about 0.08): the quadric fit is within 1e-3.
    assert np.max(np.abs(values - expected)) < 1e-3
    cosine = np.sum(gradients * np.tile(directions, (3, 1)), axis=1) / np.linalg.norm(gradients, axis=1)
    assert cosine.min() > 0.99
    assert 0.02 < field.median_radius < 0.3


def test_strays_of_a_spray(sphere_surfels):
    # The sphere's samples have none; 100 points sprayed through the cube of side 6 round it
    # are nearly all strays (of the field, or left out before it as standing off the surface of
    # their nearest), and none of the sphere's samples is.
    assert pointform.Field(sphere_surfels).strays.shape == (0, 3)
    sphere = sphere_points(8000)
    spray = np.random.default_rng(5).uniform(-3.0, 3.0, (100, 3))
    surfels, report = pointform.surfels(pointform.PointCloud(np.vstack([sphere, spray])))
    strays = pointform.Field(surfels).strays
    assert report["off_surface"] > 0
    assert 90 <= len(strays) + report["off_surface"] + report["isolated"] <= 100
    kept, kept_report = pointform.surfels(pointform.PointCloud(np.vstack([sphere, spray])),
                                          keep_off_surface=True)
    assert kept_report["off_surface"] == 0 and len(kept) >= len(surfels) + report["off_surface"]
    assert np.all(np.abs(np.linalg.norm(strays, axis=1) - 1.0) > 0.05)
    assert pointform.scene("sphere([0,0,0], 1)").strays is None


def test_every_fit_and_defined(sphere_surfels):
    inside_far = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    for fit in ("raw", "centroid", "blend", "quadric"):
        field = pointform.Field(sphere_surfels, fit=fit)
        values, _, defined = field.evaluate(inside_far, defined=True)
        assert defined.dtype == bool and not defined.any()  # beyond every influence radius
        assert values[0] < -0.9 and values[1] > 1.9  # inside negative, outside positive
    with pytest.raises(pointform.InvalidInput, match="fit|plane"):
        pointform.Field(sphere_surfels, fit="cubic")


def test_field_ends_past_a_rim_as_asked():
    # A plane sampled on a jittered grid with a round hole of radius 0.2: the default field
    # ends a quarter of a radius past the rim; rim_reach=1 reaches a whole radius into the hole.
    g = np.arange(60) * 0.02
    x, y = np.meshgrid(g, g)
    jitter = np.random.default_rng(11).uniform(-0.006, 0.006, (x.size, 2))
    points = np.stack([x.ravel() + jitter[:, 0], y.ravel() + jitter[:, 1], np.full(x.size, 0.5)],
                      axis=1)
    centre = np.array([0.6, 0.6, 0.5])
    points = points[np.linalg.norm(points - centre, axis=1) >= 0.2]
    surfels, _ = pointform.surfels(pointform.PointCloud(points))
    field = pointform.Field(surfels)
    paper = pointform.Field(surfels, rim_reach=1.0)
    r = field.median_radius
    angles = np.linspace(0.0, 2.0 * np.pi, 24, endpoint=False)
    into = centre + (0.2 - 0.6 * r) * np.stack([np.cos(angles), np.sin(angles), 0 * angles], 1)
    assert not field.evaluate(into, defined=True)[2].any()
    assert paper.evaluate(into, defined=True)[2].all()
    with pytest.raises(pointform.InvalidInput, match="rim_reach"):
        pointform.Field(surfels, rim_reach=0.0)


def cube_surface(n, seed):
    """n points uniform on the surface of the cube [-0.5, 0.5]^3."""
    rng = np.random.default_rng(seed)
    points = rng.uniform(-0.5, 0.5, (n, 3))
    axis = rng.integers(0, 3, n)
    points[np.arange(n), axis] = rng.choice([-0.5, 0.5], n)
    return points


def test_crease_fits_meet_the_faces_of_a_cube():
    # Raw points of a cube (normals estimated: tilted at the edges): with each sample's surface
    # fitted to its own face (the default) the field on the true surface near the edges is
    # closer to zero than with the principal normals' quadrics (crease_fit=False): 6-8% on
    # average within 0.01-0.1 of an edge, at 20k and 50k samples.
    surfels, _ = pointform.surfels(pointform.PointCloud(cube_surface(20000, 4)))
    truth = cube_surface(5000, 9)
    near_edges = truth[(np.abs(truth) > 0.45).sum(axis=1) >= 2]
    errors = {}
    for crease_fit in (True, False):
        values, _, defined = pointform.Field(surfels, crease_fit=crease_fit).evaluate(
            near_edges, defined=True)
        assert defined.all()
        errors[crease_fit] = np.abs(values).mean()
    assert errors[True] < 0.97 * errors[False], errors


def test_query_dtypes_and_orders_give_the_same_values(sphere_surfels):
    field = pointform.Field(sphere_surfels)
    points, _ = radial_queries([0.97, 1.02], n=50)
    points32 = points.astype(np.float32)
    reference, reference_gradients = field.evaluate(points32.astype(np.float64))
    for variant in (points32, np.asfortranarray(points32.astype(np.float64)),
                    points32.astype(np.float64)[:, ::-1][:, ::-1], points32.tolist()):
        values, gradients = field.evaluate(variant)
        assert np.array_equal(values, reference)
        assert np.array_equal(gradients, reference_gradients)
    values, gradients = field.evaluate(np.zeros((0, 3)))
    assert values.shape == (0,) and gradients.shape == (0, 3)


def test_bad_queries_and_fields(sphere_surfels, sphere_cloud):
    field = pointform.Field(sphere_surfels)
    with pytest.raises(pointform.InvalidInput, match=r"points\[1\] is not finite"):
        field.evaluate(np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0]]))
    with pytest.raises(ValueError, match="N by 3"):
        field.evaluate(np.zeros((4, 4)))
    with pytest.raises(ValueError, match="normals|radii"):
        pointform.Field(sphere_cloud)  # no normals or radii


def test_scene_fields_are_exact():
    field = pointform.scene("sphere([0, 0, 0], 1)")
    points, _ = radial_queries([0.5, 1.0, 2.0], n=20)
    values, gradients = field.evaluate(points)
    assert np.allclose(values, np.linalg.norm(points, axis=1) - 1.0, rtol=0, atol=1e-12)
    lo, hi = field.bounds()
    assert np.all(lo <= -1.0) and np.all(hi >= 1.0)
    assert field.median_radius is None
    with pytest.raises(pointform.InvalidInput, match="expression:1:"):
        pointform.scene("sphere([0, 0, 0], 1")
    with pytest.raises(pointform.InvalidInput, match="did you mean 'sphere'"):
        pointform.scene("spher([0, 0, 0], 1)")


def noisy_slab(n=100000, thickness=0.06, noise=0.018, seed=3):
    """Raw points of a 2 x 2 plate `thickness` thick (its top and bottom faces only) under
    Gaussian noise of `noise` (2 sampling steps at 100k): the faces, 3.3 deviations apart, merge
    into one slab of samples."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(-1.0, 1.0, (n, 2))
    z = np.where(rng.random(n) < 0.5, 0.5, -0.5) * thickness
    return np.column_stack([xy, z]) + rng.normal(0.0, noise, (n, 3))


def test_noise_scale_fits_make_one_sheet_of_a_noisy_slab():
    surfels, _ = pointform.surfels(pointform.PointCloud(noisy_slab()))
    rng = np.random.default_rng(5)
    xy = rng.uniform(-0.8, 0.8, (200, 2))
    z = np.linspace(-0.08, 0.08, 161)
    lines = np.concatenate([np.column_stack([np.full(z.size, x), np.full(z.size, y), z])
                            for x, y in xy])

    def crossed_once(field):
        values, _, defined = field.evaluate(lines, defined=True)
        once = 0
        for v, d in zip(values.reshape(len(xy), z.size), defined.reshape(len(xy), z.size)):
            signs = np.sign(v[d])
            once += int(np.count_nonzero(signs[1:] != signs[:-1]) == 1)
        return once / len(xy)

    assert crossed_once(pointform.Field(surfels)) < 0.8  # fits narrower than the slab
    assert crossed_once(pointform.Field(surfels, noise_scale=True)) > 0.95
    # reconstruct finds the sponge and makes the field again, as the CLI does.
    report = pointform.reconstruct(pointform.PointCloud(noisy_slab())).report
    assert report["field_noise_scale"]["refitted"]
    assert report["field_noise_scale"]["sponge_genus"] >= 64
    assert report["base_mesh"]["euler_characteristic"] == 1  # one sheet, one rim
