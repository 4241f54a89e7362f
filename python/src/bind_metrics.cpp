// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/metrics/surface_sampling.h"
#include "pointform/report/report_json.h"

#include "common.h"

#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

namespace pointform::python {
namespace {

/// A shape to compare and how Python named it: a file (read as `pointform distance` reads it:
/// a mesh if it has faces, else a point set), a PointCloud (measured in place) or a Mesh.
struct Shape
{
    std::shared_ptr<const TriMesh> mesh;
    std::shared_ptr<const Cloud> cloud;
    py::object file = py::none();

    [[nodiscard]] ShapeRef ref() const { return mesh ? ShapeRef(*mesh) : ShapeRef(cloud->view); }
};

/// Turns a path, PointCloud or Mesh into a shape; a file is read with the GIL released.
Shape shape_from(const py::object& object, const char* name)
{
    Shape shape;
    if (py::isinstance<TriMesh>(object))
        shape.mesh = object.cast<std::shared_ptr<TriMesh>>();
    else if (py::isinstance<Cloud>(object))
        shape.cloud = object.cast<std::shared_ptr<Cloud>>();
    else if (py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__"))
    {
        const std::string path =
            py::module_::import("os").attr("fspath")(object).cast<std::string>();
        auto mesh = std::make_shared<TriMesh>();
        {
            py::gil_scoped_release release;
            ReadResult read = read_geometry(path);
            if (read.points.empty())
                throw InvalidInput(path + ": the file has no points");
            mesh->vertices = std::move(read.points);
            mesh->triangles = std::move(read.triangles);
        }
        shape.mesh = mesh;
        shape.file = py::str(path);
    }
    else
        throw InvalidInput(std::string(name) + ": expected a path, PointCloud or Mesh, got " +
                           py::str(py::type::of(object)).cast<std::string>());
    const ShapeRef ref = shape.ref();
    if (ref.points.empty())
        throw InvalidInput(std::string(name) + ": the shape has no points");
    if (ref.mesh != nullptr && !(surface_area(*ref.mesh) > 0.0))
        throw InvalidInput(std::string(name) + ": every triangle of the mesh has zero area");
    return shape;
}

py::dict shape_dict(const Shape& shape, std::size_t samples)
{
    nlohmann::json out = report_json(shape.ref(), samples);
    py::dict dict = to_python(out);
    dict["file"] = shape.file;
    return dict;
}

} // namespace

void bind_metrics(py::module_& m)
{
    m.def(
        "distance",
        [](const py::object& a, const py::object& b, long long samples, std::uint64_t seed,
           const std::vector<double>& fscore) {
            if (samples < 1)
                throw InvalidInput("samples must be at least 1, got " + std::to_string(samples));
            const Shape shape_a = shape_from(a, "a");
            const Shape shape_b = shape_from(b, "b");
            const auto sample_total = static_cast<std::size_t>(samples);
            const DistanceComparison result =
                run_interruptible([&](const ProgressCallback& progress) {
                    return compare(shape_a.ref(), shape_b.ref(),
                                   {.samples = sample_total,
                                    .seed = seed,
                                    .include_vertices = true,
                                    .fscore_thresholds = fscore,
                                    .progress = progress});
                });
            py::dict out = to_python(report_json(result));
            out["a"] = shape_dict(shape_a, sample_total);
            out["b"] = shape_dict(shape_b, sample_total);
            out["samples_per_mesh"] = sample_total;
            out["seed"] = seed;
            return out;
        },
        py::arg("a"), py::arg("b"), py::kw_only(), py::arg("samples") = 100000, py::arg("seed") = 1,
        py::arg("fscore") = std::vector<double>{},
        "distance(a, b, *, samples=100000, seed=1, fscore=()) -> dict\n\n"
        "Measures two shapes against each other as `pointform distance --json` does (MeshLab's "
        "Metro): a and b are paths (a file with faces is a mesh, else a point set), PointClouds "
        "or Meshes. A mesh is sampled area-uniformly (`samples` random points plus its "
        "vertices) and measured against exactly; a point set is used as it is. Returns the "
        "figures of the CLI's JSON (its run report aside): a, b (file, kind, points, faces, "
        "samples), samples_per_mesh, seed, diagonal, absolute and relative_to_diagonal "
        "(a_to_b, b_to_a, symmetric: count min max mean rms p50 p90 p99; hausdorff; chamfer), "
        "fscore (thresholds as fractions of the diagonal).");
}

} // namespace pointform::python
