# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""PointCloud and Mesh: construction from numpy, views, and bad input."""

import gc

import numpy as np
import pytest

import pointform
from conftest import sphere_points


def test_float32_positions_are_taken_as_they_are():
    p = sphere_points(100).astype(np.float32)
    cloud = pointform.PointCloud(p)
    assert len(cloud) == 100
    assert cloud.positions.dtype == np.float32 and cloud.positions.shape == (100, 3)
    assert np.array_equal(cloud.positions, p)
    assert np.array_equal(cloud.origin, np.zeros(3))
    assert cloud.normals is None and cloud.colors is None and cloud.radii is None


def test_float64_positions_are_recentred_like_the_readers():
    p = sphere_points(50) + np.array([500000.25, 4200000.75, 12.0])  # georeferenced
    cloud = pointform.PointCloud(p)
    assert np.array_equal(cloud.origin, np.round(p[0]))
    # Relative float32 storage keeps sub-millimetre precision that float32 world values lose.
    assert np.max(np.abs(cloud.world() - p)) < 1e-6
    assert np.max(np.abs(p.astype(np.float32).astype(np.float64) - p)) > 1e-3


def test_other_dtypes_and_orders_are_converted_once():
    p = sphere_points(40)
    reference = pointform.PointCloud(p.astype(np.float32))
    for variant in (np.asfortranarray(p.astype(np.float32)), p.astype(np.float32)[::-1][::-1],
                    np.ascontiguousarray(p[:, [2, 1, 0]])[:, [2, 1, 0]],
                    p.astype(np.float32).astype(">f4")):
        cloud = pointform.PointCloud(variant, origin=np.zeros(3))
        assert np.array_equal(cloud.positions, reference.positions)
    ints = pointform.PointCloud(np.array([[0, 0, 0], [1, 2, 3]], dtype=np.int64))
    assert np.array_equal(ints.world(), [[0, 0, 0], [1, 2, 3]])


def test_attributes():
    p = sphere_points(30).astype(np.float32)
    colors = np.arange(90, dtype=np.uint8).reshape(30, 3)
    radii = np.linspace(0.1, 0.2, 30)
    cloud = pointform.PointCloud(p, normals=p, colors=colors, radii=radii)
    assert np.array_equal(cloud.normals, p)
    assert np.array_equal(cloud.colors, colors) and cloud.colors.dtype == np.uint8
    assert np.array_equal(cloud.radii, radii.astype(np.float32))
    lo, hi = cloud.bounds()
    assert np.all(lo <= p.min(axis=0)) and np.all(hi >= p.max(axis=0))


def test_arrays_are_read_only_views_tied_to_the_owner():
    cloud = pointform.PointCloud(sphere_points(20), normals=sphere_points(20))
    first, second = cloud.positions, cloud.positions
    assert np.shares_memory(first, second)
    assert np.shares_memory(cloud.normals, cloud.normals)
    for array in (first, cloud.normals, cloud.origin):
        assert not array.flags.writeable
        with pytest.raises(ValueError):
            array[0] = 1.0
    expected = first.copy()
    del cloud
    gc.collect()
    assert np.array_equal(first, expected)  # the view keeps the cloud alive


def test_arrays_in_the_library_layout_are_used_in_place():
    p = np.ascontiguousarray(sphere_points(300), dtype=np.float32)
    n = p.copy()
    colors = np.arange(900, dtype=np.uint8).reshape(300, 3)
    radii = np.full(300, 0.05, dtype=np.float32)
    cloud = pointform.PointCloud(p, normals=n, colors=colors, radii=radii)
    for given, held in ((p, cloud.positions), (n, cloud.normals), (colors, cloud.colors),
                        (radii, cloud.radii)):
        assert np.shares_memory(given, held)  # no copy
        assert not held.flags.writeable
    expected = p.copy()
    del p, n, colors, radii
    gc.collect()
    assert np.array_equal(cloud.positions, expected)  # the cloud keeps the arrays alive


def test_other_layouts_are_converted_not_shared():
    p = sphere_points(300).astype(np.float32)
    unaligned = np.frombuffer(b"\0" + p.tobytes(), dtype=np.float32, offset=1).reshape(300, 3)
    for variant, origin in ((sphere_points(300), None), (np.asfortranarray(p), None),
                            (p[::2], None), (unaligned, None), (p, np.ones(3))):
        cloud = pointform.PointCloud(variant, origin=origin)
        assert not np.shares_memory(variant, cloud.positions)
    mesh = pointform.Mesh(p[:3].copy(), np.array([[0, 1, 2]]))
    assert not np.shares_memory(p, mesh.vertices)  # a Mesh owns its vertices


def test_in_place_and_converted_clouds_give_the_same_results():
    p = np.ascontiguousarray(sphere_points(3000), dtype=np.float32)
    in_place = pointform.PointCloud(p)
    converted = pointform.PointCloud(np.asfortranarray(p))
    assert np.shares_memory(p, in_place.positions)
    assert not np.shares_memory(p, converted.positions)
    a, report_a = pointform.surfels(in_place)
    b, report_b = pointform.surfels(converted)
    assert report_a == report_b
    for x, y in ((a.positions, b.positions), (a.normals, b.normals), (a.radii, b.radii)):
        assert np.array_equal(x, y)
    # Surfels given in place (normals and radii float32 C order) make the same field.
    normals, radii = np.array(a.normals), np.array(a.radii)
    again = pointform.PointCloud(np.array(a.positions), normals=normals, radii=radii)
    assert np.shares_memory(normals, again.normals) and np.shares_memory(radii, again.radii)
    queries = sphere_points(50, radius=1.2)
    assert np.array_equal(pointform.Field(a).evaluate(queries)[0],
                          pointform.Field(again).evaluate(queries)[0])
    assert pointform.distance(in_place, a) == pointform.distance(converted, b)


def test_mesh():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)
    mesh = pointform.Mesh(vertices, faces)
    assert mesh.vertex_count == 4 and mesh.face_count == 4
    assert mesh.faces.dtype == np.uint32 and np.array_equal(mesh.faces, faces)
    assert np.array_equal(mesh.vertices, vertices)
    assert np.shares_memory(mesh.faces, mesh.faces) and not mesh.faces.flags.writeable
    assert len(mesh.points()) == 4


@pytest.mark.parametrize(
    "positions, message",
    [
        (np.zeros((5, 2)), "N by 3"),
        (np.zeros(9), "N by 3"),
        (np.zeros((0, 3)), "empty"),
        (np.array([[0, 0, 0], [np.nan, 1, 2]]), r"positions\[1\] is not finite"),
        (np.array([[0, 0, 0], [np.inf, 1, 2]], dtype=np.float32), r"positions\[1\] is not finite"),
        (np.zeros((4, 3), dtype=complex), "real numbers"),
        (np.array([["a", "b", "c"]]), "real numbers"),
        ("not an array", "real numbers"),
        (np.zeros((4, 3), dtype=bool), "real numbers"),
        (np.array([[0, 0, 0], [1e39, 0, 0]]), r"positions\[1\] .* out of the float32 range"),
    ],
)
def test_bad_positions(positions, message):
    with pytest.raises(pointform.InvalidInput, match=message) as error:
        pointform.PointCloud(positions)
    assert isinstance(error.value, ValueError) and isinstance(error.value, pointform.Error)


def test_bad_attributes():
    p = sphere_points(10)
    with pytest.raises(ValueError, match="normals: expected 10 rows"):
        pointform.PointCloud(p, normals=p[:5])
    with pytest.raises(ValueError, match=r"normals\[3\] is not finite"):
        n = p.copy()
        n[3, 1] = np.nan
        pointform.PointCloud(p, normals=n)
    with pytest.raises(ValueError, match=r"colors\[0\] has a channel out of 0-255: 300"):
        pointform.PointCloud(p, colors=np.full((10, 3), 300))
    with pytest.raises(ValueError, match="colors: expected integers"):
        pointform.PointCloud(p, colors=np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r"radii\[0\] must be positive"):
        pointform.PointCloud(p, radii=np.zeros(10))
    with pytest.raises(ValueError, match="radii: expected 10 values"):
        pointform.PointCloud(p, radii=np.ones(3))
    with pytest.raises(ValueError, match="origin"):
        pointform.PointCloud(p, origin=[0, np.nan, 0])


@pytest.mark.parametrize(
    "faces, message",
    [
        (np.array([[0, 1, 4]]), r"faces\[0\] = \(0, 1, 4\): vertex index out of range"),
        (np.array([[0, 1, 2], [0, -1, 2]]), r"faces\[1\] = \(0, -1, 2\)"),
        (np.array([[0, 1, 2.0]]), "integer vertex indices"),
        (np.zeros((0, 3), dtype=np.int32), "empty"),
        (np.array([0, 1, 2]), "F by 3"),
    ],
)
def test_bad_faces(faces, message):
    vertices = np.eye(4, 3)
    with pytest.raises(pointform.InvalidInput, match=message):
        pointform.Mesh(vertices, faces)


def test_threads():
    before = pointform.thread_count()
    pointform.set_thread_count(1)
    assert pointform.thread_count() == 1
    pointform.set_thread_count(0)
    assert pointform.thread_count() == before
    with pytest.raises(ValueError):
        pointform.set_thread_count(-2)
