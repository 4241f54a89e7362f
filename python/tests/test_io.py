# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""read, read_mesh, read_points, write: the library's readers and writers, and IoError."""

import os

import numpy as np
import pytest

import pointform
from conftest import BUNNY_SCAN, BUNNY_SMALL, run_cli, sphere_points


def test_read_gives_a_mesh_for_files_with_faces_and_points_otherwise(tmp_path):
    mesh = pointform.read(BUNNY_SMALL)
    assert isinstance(mesh, pointform.Mesh)
    assert mesh.face_count > 0 and mesh.faces.max() < mesh.vertex_count
    points = tmp_path / "points.xyz"
    pointform.write(points, mesh.points())
    cloud = pointform.read(str(points))
    assert isinstance(cloud, pointform.PointCloud) and len(cloud) == mesh.vertex_count
    assert np.array_equal(cloud.world(), mesh.world())


def test_read_matches_the_cli_info():
    info = run_cli("info", BUNNY_SCAN, "--json", json_output=True)
    mesh = pointform.read_mesh(BUNNY_SCAN)
    assert mesh.vertex_count == info["points"]
    assert mesh.face_count == info["faces"]


def test_write_round_trips_every_attribute(tmp_path):
    p = sphere_points(200).astype(np.float32)
    cloud = pointform.PointCloud(p, normals=p, colors=np.full((200, 3), 7, dtype=np.uint8),
                                 radii=np.full(200, 0.05))
    for name, ascii in (("c.ply", False), ("a.ply", True)):
        path = tmp_path / name
        pointform.write(path, cloud, ascii=ascii)
        back = pointform.read(path)
        assert np.allclose(back.world(), cloud.world(), rtol=0, atol=1e-7)
        assert np.allclose(back.normals, cloud.normals, rtol=0, atol=1e-6)  # unit on reading
        assert np.array_equal(back.colors, cloud.colors)
        assert np.array_equal(back.radii, cloud.radii)
    mesh = pointform.read_mesh(BUNNY_SMALL)
    for name in ("m.ply", "m.off", "m.obj"):
        pointform.write(tmp_path / name, mesh)
        back = pointform.read_mesh(tmp_path / name)
        assert np.array_equal(back.faces, mesh.faces)
        assert np.allclose(back.world(), mesh.world(), rtol=0, atol=1e-6)


def test_io_errors_are_oserrors_with_the_library_message(tmp_path):
    missing = tmp_path / "missing.ply"
    with pytest.raises(pointform.IoError, match="does not exist") as error:
        pointform.read(missing)
    assert isinstance(error.value, OSError) and isinstance(error.value, pointform.Error)
    assert error.value.path == str(missing)
    truncated = tmp_path / "truncated.ply"
    truncated.write_bytes(open(BUNNY_SMALL, "rb").read()[:2000])
    with pytest.raises(OSError, match="truncated.ply"):
        pointform.read(truncated)
    with pytest.raises(pointform.IoError, match="no faces|faces"):
        points = tmp_path / "p.xyz"
        points.write_text("0 0 0\n1 0 0\n0 1 0\n")
        pointform.read_mesh(points)
    with pytest.raises(pointform.IoError):
        pointform.write(tmp_path / "no_such_dir" / "x.ply", pointform.read(BUNNY_SMALL))
    with pytest.raises(pointform.IoError):
        pointform.write(tmp_path / "x.unknown", pointform.read(BUNNY_SMALL))
    assert not os.path.exists(tmp_path / "x.unknown")
    with pytest.raises(pointform.InvalidInput, match="expected a PointCloud"):
        pointform.write(tmp_path / "y.ply", np.zeros((3, 3)))
