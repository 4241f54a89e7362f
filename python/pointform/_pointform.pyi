# SPDX-License-Identifier: MIT
# Copyright (c) 2026 the pointform authors
# Type stub of the extension module pointform._pointform (re-exported by pointform).

import os
from typing import Any, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Array = npt.ArrayLike

__version__: str
default_neighbors: int
default_radius_scale: float

class Error(RuntimeError): ...
class InvalidInput(Error, ValueError): ...
class IoError(Error, OSError):
    path: str
class SolverError(Error): ...
class TopologyError(Error): ...
class Cancelled(Error): ...

def thread_count() -> int: ...
def set_thread_count(threads: int) -> None: ...

class PointCloud:
    def __init__(
        self,
        positions: _Array,
        *,
        normals: _Array | None = None,
        colors: _Array | None = None,
        radii: _Array | None = None,
        origin: _Array | None = None,
        sensor: _Array | None = None,
    ) -> None: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def normals(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def colors(self) -> npt.NDArray[np.uint8] | None: ...
    @property
    def radii(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def origin(self) -> npt.NDArray[np.float64]: ...
    @property
    def sensor(self) -> Tuple[float, float, float] | None: ...
    def world(self) -> npt.NDArray[np.float64]: ...
    def bounds(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    def __len__(self) -> int: ...

class Mesh:
    def __init__(
        self,
        vertices: _Array,
        faces: _Array,
        *,
        normals: _Array | None = None,
        colors: _Array | None = None,
        origin: _Array | None = None,
    ) -> None: ...
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def normals(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def colors(self) -> npt.NDArray[np.uint8] | None: ...
    @property
    def origin(self) -> npt.NDArray[np.float64]: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    def world(self) -> npt.NDArray[np.float64]: ...
    def points(self) -> PointCloud: ...
    def bounds(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...

def read(path: _Path) -> PointCloud | Mesh: ...
def read_mesh(path: _Path) -> Mesh: ...
def read_points(path: _Path) -> PointCloud: ...
def write(path: _Path, shape: PointCloud | Mesh | Hierarchy, *, ascii: bool = False) -> None: ...

def surfels(
    cloud: PointCloud,
    *,
    k: int = 16,
    radius_scale: float = 1.5,
    orient: str = "auto",
    reestimate: bool = False,
    sharp_creases: bool = False,
    keep_off_surface: bool = False,
) -> Tuple[PointCloud, dict[str, Any]]: ...
def surfels_from_mesh(
    mesh: Mesh, *, samples: int = 0, seed: int = 1, k: int = 16, radius_scale: float = 1.5
) -> Tuple[PointCloud, dict[str, Any]]: ...

class Field:
    def __init__(
        self,
        surfels: PointCloud,
        *,
        fit: str = "quadric",
        far_grid: bool = True,
        rim_reach: float = 0.25,
        crease_fit: bool = True,
        noise_scale: bool = False,
    ) -> None: ...
    @overload
    def evaluate(
        self, points: _Array
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @overload
    def evaluate(
        self, points: _Array, *, defined: bool
    ) -> Tuple[npt.NDArray[np.float64], ...]: ...
    def bounds(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def median_radius(self) -> float | None: ...
    @property
    def strays(self) -> npt.NDArray[np.float64] | None: ...

def scene(expression_or_file: str, *, fit: str = "quadric") -> Field: ...

class Hierarchy:
    @property
    def level_count(self) -> int: ...
    @property
    def finest_level(self) -> int: ...
    def level(self, level: int) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...
    def level_mesh(self, level: int) -> Mesh: ...
    def vertex_count(self, level: int) -> int: ...
    def face_count(self, level: int) -> int: ...
    @property
    def origin(self) -> npt.NDArray[np.float64]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def base_faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def level_offsets(self) -> npt.NDArray[np.uint64]: ...
    @property
    def parent_edges(self) -> npt.NDArray[np.uint32]: ...
    @property
    def report(self) -> dict[str, Any] | None: ...
    def save(self, path: _Path) -> None: ...
    def deform(
        self,
        *,
        edit: dict[str, Any] | _Path | None = None,
        lattice: dict[str, Any] | _Path | None = None,
        plain: bool = False,
    ) -> Hierarchy: ...
    def details(self, normal_tolerance: float = 0.1) -> dict[str, Any]: ...
    def texture(
        self,
        *,
        level: int | None = None,
        image: npt.NDArray[np.uint8] | _Path | None = None,
        bake_colors: PointCloud | _Path | None = None,
        normal_map_level: int | None = None,
        size: int = 0,
    ) -> Textured: ...
    def export_levels(self, levels: list[int] | None = None) -> Textured: ...

class Textured:
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def origin(self) -> Tuple[float, float, float]: ...
    @property
    def uvs(self) -> npt.NDArray[np.float32] | None: ...
    @property
    def normals(self) -> npt.NDArray[np.float32]: ...
    @property
    def lods(self) -> list[npt.NDArray[np.uint32]]: ...
    @property
    def lod_vertex_counts(self) -> list[int]: ...
    @property
    def lod_levels(self) -> list[int]: ...
    @property
    def base_color(self) -> npt.NDArray[np.uint8] | None: ...
    @property
    def normal_map(self) -> npt.NDArray[np.uint8] | None: ...
    @property
    def report(self) -> dict[str, Any] | None: ...
    def save(self, path: _Path) -> None: ...

def load_hierarchy(path: _Path) -> Hierarchy: ...
def fill_holes(mesh: Mesh, *, max_share: float = 0.05) -> tuple[Mesh, dict[str, object]]: ...
def reconstruct(
    cloud: PointCloud,
    *,
    levels: int | None = None,
    base_faces: int | None = None,
    stop_rule: str = "auto",
    fit: str = "quadric",
    resolution: int = 0,
    cell: float = 0.0,
    min_component_samples: int | None = None,
    base_mesh: _Path | None = None,
    k: int = 16,
    radius_scale: float = 1.5,
    orient: str = "auto",
    predictor: str = ...,
    relax_iterations: int = ...,
    relaxation: str = ...,
    base_triangles: object | None = None,
    fill_holes: float = 0.05,
    rim_reach: float = 0.25,
    denoise_rounds: int = 10,
    hole_fairing: bool = True,
    max_handle: float = 6.0,
    face_fit: bool = True,
) -> Hierarchy: ...
def remesh(
    mesh: Mesh,
    *,
    levels: int | None = None,
    base_faces: int | None = None,
    stop_rule: str = "auto",
    fit: str = "quadric",
    samples: int = 0,
    seed: int = 1,
    k: int = 16,
    radius_scale: float = 1.5,
    denoise_rounds: int = 10,
) -> Hierarchy: ...
def model(
    expression_or_file: str,
    *,
    resolution: int = 0,
    cell: float = 0.0,
    bounds: Tuple[Sequence[float], Sequence[float]] | None = None,
    fit: str = "quadric",
    semi_regular: bool = False,
    levels: int | None = None,
    base_faces: int | None = None,
) -> Mesh: ...
def distance(
    a: _Path | PointCloud | Mesh,
    b: _Path | PointCloud | Mesh,
    *,
    samples: int = 100000,
    seed: int = 1,
    fscore: Sequence[float] = (),
) -> dict[str, Any]: ...
