# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
"""Hierarchy.deform and Hierarchy.details: bit for bit `pointform deform`, bad edits refused."""

import json

import numpy as np
import pytest

import pointform
from conftest import BUNNY_SMALL, run_cli


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    hierarchy = pointform.reconstruct(pointform.read_points(BUNNY_SMALL), levels=2)
    path = tmp_path_factory.mktemp("multires") / "small.pfh"
    hierarchy.save(path)
    return pointform.load_hierarchy(path), path


def ball_edit(h, level=1, lift=0.01):
    vertices, _ = h.level(level)
    centre = vertices[3]
    return {"level": level,
            "handles": [{"vertices": [3], "translate": [0.0, lift, 0.0]}],
            "region": {"ball": {"center": centre.tolist(), "radius": 0.05}}}


def test_deform_is_the_clis(small, tmp_path):
    h, path = small
    edit = ball_edit(h)
    edit_path = tmp_path / "edit.json"
    edit_path.write_text(json.dumps(edit))
    out = tmp_path / "cli.pfh"
    cli = run_cli("deform", path, "-o", out, "--edit", edit_path, "--json", json_output=True)
    from_dict = h.deform(edit=edit)
    from_file = h.deform(edit=edit_path)
    expected = pointform.load_hierarchy(out)
    for d in (from_dict, from_file):
        assert np.array_equal(d.positions, expected.positions)
        assert d.report["deformation"] == cli["deformation"]
        assert d.report["details"] == cli["details"]
        assert d.report["mode"] == "edit"
    # The handle moved by the translation, the input did not.
    assert np.allclose(from_dict.positions[3] - h.positions[3], [0.0, 0.01, 0.0], atol=1e-15)
    moved = cli["deformation"]["levels"]
    assert moved[-1]["moved"] > 0 and moved[-1]["moved"] < moved[-1]["vertices"]
    assert not np.array_equal(from_dict.positions, h.positions)


def test_lattice_at_rest_and_plain(small):
    h, _ = small
    world, _ = h.level(-1)
    lo, hi = world.min(axis=0) - 0.01, world.max(axis=0) + 0.01
    degree = [2, 1, 1]
    points = [[lo[0] + (hi[0] - lo[0]) * i / 2, lo[1] + (hi[1] - lo[1]) * j, lo[2] + (hi[2] - lo[2]) * k]
              for k in range(2) for j in range(2) for i in range(3)]
    lattice = {"min": lo.tolist(), "max": hi.tolist(), "degree": degree, "level": 1,
               "control_points": points}
    rest = h.deform(lattice=lattice)
    diagonal = np.linalg.norm(hi - lo)
    assert np.abs(rest.positions - h.positions).max() <= 1e-12 * diagonal
    lattice["control_points"][1][1] += 0.02
    plain = h.deform(lattice=lattice, plain=True)
    riding = h.deform(lattice=lattice)
    assert plain.report["mode"] == "lattice (plain)"
    assert riding.report["mode"] == "lattice (details)"
    assert not np.array_equal(plain.positions, riding.positions)


def test_details(small):
    h, _ = small
    details = h.details()
    assert [row["level"] for row in details["levels"]] == [1, 2]
    for row in details["levels"]:
        assert 0.0 <= row["normal_share"] <= 1.0
        assert row["max_length"] >= row["mean_length"] > 0.0
    assert h.details(normal_tolerance=1.0)["levels"][0]["normal_share"] == 1.0


def test_bad_edits(small, tmp_path):
    h, _ = small
    with pytest.raises(pointform.InvalidInput, match="not a vertex of level 1"):
        h.deform(edit={"level": 1, "handles": [{"vertices": [10**8], "translate": [0, 0, 1]}]})
    with pytest.raises(pointform.InvalidInput, match="not valid JSON"):
        h.deform(edit={"level": 1, "handles": [{"vertices": [1], "translate": [float("nan"), 0, 0]}]})
    with pytest.raises(pointform.InvalidInput, match="level 9 does not exist"):
        h.deform(edit={"level": 9})
    with pytest.raises(pointform.InvalidInput, match="needs 8 control points"):
        h.deform(lattice={"min": [-1, -1, -1], "max": [1, 1, 1], "degree": [1, 1, 1],
                          "control_points": [[0, 0, 0]]})
    with pytest.raises(pointform.InvalidInput):
        h.deform()
    with pytest.raises(pointform.InvalidInput):
        h.deform(edit=ball_edit(h), plain=True)
    with pytest.raises(pointform.IoError):
        h.deform(edit=tmp_path / "missing.json")


def test_texture_and_export_are_the_clis(small, tmp_path):
    h, path = small
    cli_glb = tmp_path / "cli.glb"
    cli = run_cli("texture", path, "-o", cli_glb, "--size", 256, "--json", json_output=True)
    textured = h.texture(size=256)
    assert textured.report["levels"] == cli["levels"]
    assert textured.report["atlas"] == cli["atlas"]
    mine = tmp_path / "py.glb"
    textured.save(mine)
    assert mine.read_bytes() == cli_glb.read_bytes()
    assert textured.base_color.shape == (256, 256, 3)
    assert textured.uvs.min() >= 0.0 and textured.uvs.max() <= 1.0
    assert textured.lod_vertex_counts[-1] == len(textured.positions)
    assert [len(f) for f in textured.lods] == [h.face_count(i) for i in range(h.level_count)]
    assert textured.normal_map is None

    textured.save(tmp_path / "py.obj")
    for name in ("py.obj", "py.mtl", "py_color.png"):
        assert (tmp_path / name).exists()

    cli_levels = tmp_path / "cli_levels.glb"
    run_cli("export", path, "-o", cli_levels, "-q")
    chain = h.export_levels()
    chain.save(tmp_path / "py_levels.glb")
    assert (tmp_path / "py_levels.glb").read_bytes() == cli_levels.read_bytes()
    assert chain.uvs is None


def test_texture_sources_and_bad_input(small, tmp_path):
    h, _ = small
    image = np.zeros((8, 8, 3), dtype=np.uint8)
    image[:, 4:] = 255
    painted = h.texture(image=image, size=128)
    assert painted.base_color[:, :16].mean() < painted.base_color[:, -16:].mean()
    light = h.texture(normal_map_level=1, size=128)
    assert light.normal_map.shape == (128, 128, 3) and light.report["normal_map"]
    assert len(light.lods) == 1
    scan = pointform.read_points(BUNNY_SMALL)
    with pytest.raises(pointform.InvalidInput, match="colours"):
        h.texture(bake_colors=scan)
    colored = pointform.PointCloud(scan.positions, colors=np.full((len(scan.positions), 3), 200, np.uint8),
                                   origin=scan.origin)
    # Every triangle gets its colour, even in an atlas so tight that most charts hold no texel
    # centre (128 texels a side: the bake covers every texel a chart touches).
    for size in (128, 256):
        baked = h.texture(bake_colors=colored, size=size)
        assert baked.report["bake"]["rms_color_error"] < 1.0
    # Where the gutters alone fill the texture the charts would have no size: refused.
    with pytest.raises(pointform.InvalidInput, match="do not fit"):
        h.texture(size=32)
    with pytest.raises(pointform.InvalidInput, match="does not exist"):
        h.texture(level=7)
    with pytest.raises(pointform.InvalidInput):
        h.texture(size=8)
    with pytest.raises(pointform.IoError):
        h.texture(image=tmp_path / "missing.png")
    with pytest.raises(pointform.InvalidInput):
        h.export_levels([2, 1])
