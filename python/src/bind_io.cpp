// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include "common.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>

namespace pointform::python {

void bind_io(py::module_& m)
{
    m.def(
        "read",
        [](const std::filesystem::path& path) -> py::object {
            ReadResult read;
            {
                py::gil_scoped_release release;
                read = read_geometry(path);
            }
            if (read.triangles.empty())
                return py::cast(owned_cloud(std::move(read.points)));
            auto mesh = std::make_shared<TriMesh>();
            mesh->vertices = std::move(read.points);
            mesh->triangles = std::move(read.triangles);
            return py::cast(mesh);
        },
        py::arg("path"),
        "read(path) -> PointCloud | Mesh\n\n"
        "Reads a point set or mesh by its extension (.ply .xyz .pts .csv .txt .pwn .off .obj "
        ".pcd .las): a Mesh if the file has faces, else a PointCloud with whatever normals, "
        "colors and radii it carries. Raises IoError (an OSError) naming the file, the line or "
        "byte offset and what is wrong.");
    m.def(
        "read_mesh",
        [](const std::filesystem::path& path) {
            py::gil_scoped_release release;
            return std::make_shared<TriMesh>(read_mesh(path));
        },
        py::arg("path"),
        "read_mesh(path) -> Mesh\n\nReads a triangle mesh (polygons are fan-triangulated). "
        "Raises IoError if the file cannot be read or has no faces.");
    m.def(
        "read_points",
        [](const std::filesystem::path& path) {
            PointCloud cloud;
            {
                py::gil_scoped_release release;
                cloud = read_point_cloud(path);
            }
            return owned_cloud(std::move(cloud));
        },
        py::arg("path"),
        "read_points(path) -> PointCloud\n\nReads the points of any supported file (a mesh "
        "gives its vertices). Raises IoError.");
    m.def(
        "write",
        [](const std::filesystem::path& path, const py::object& shape, bool ascii) {
            const WriteOptions options{.ascii = ascii};
            if (py::isinstance<Cloud>(shape))
            {
                const auto cloud = shape.cast<std::shared_ptr<Cloud>>();
                py::gil_scoped_release release;
                write_point_cloud(path, cloud->view, options);
            }
            else if (py::isinstance<TriMesh>(shape))
            {
                const auto mesh = shape.cast<std::shared_ptr<TriMesh>>();
                py::gil_scoped_release release;
                write_mesh(path, *mesh, options);
            }
            else if (py::isinstance<Hierarchy>(shape))
            {
                auto& hierarchy = shape.cast<Hierarchy&>();
                py::gil_scoped_release release;
                write_hierarchy(path, hierarchy.mesh);
            }
            else
                throw InvalidInput("write: expected a PointCloud, Mesh or Hierarchy, got " +
                                   py::str(py::type::of(shape)).cast<std::string>());
        },
        py::arg("path"), py::arg("shape"), py::kw_only(), py::arg("ascii") = false,
        "write(path, shape, *, ascii=False)\n\n"
        "Writes a PointCloud (.ply or .xyz, with its normals, colors and radii), a Mesh (.ply, "
        ".off or .obj) or a Hierarchy (.pfh) by the extension, through a temporary file renamed "
        "into place: a failure never leaves a half-written file. ascii: text PLY instead of "
        "binary. Raises IoError.");
}

} // namespace pointform::python
