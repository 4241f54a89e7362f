// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/implicit/field.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/scans.h"

#include "common.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <memory>
#include <string>

namespace pointform::python {
namespace {

/// A field as Python holds it: any Field (a point field or a scene), shared.
struct FieldHandle
{
    std::shared_ptr<const Field> field;
    std::shared_ptr<const PointField> point; ///< set for a point field
    std::string description;
};

py::tuple evaluate(const FieldHandle& self, const py::object& points_object, bool with_defined)
{
    const py::array array = as_array(points_object, "points");
    std::vector<Vec3d> storage;
    const std::span<const Vec3d> points = vec3d_rows(array, "points", storage);
    const auto m = static_cast<py::ssize_t>(points.size());
    std::vector<double> values(points.size());
    std::vector<Vec3d> gradients(points.size());
    std::vector<std::uint8_t> defined(points.size());
    {
        py::gil_scoped_release release;
        std::vector<FieldSample> samples(points.size());
        self.field->evaluate(points, samples);
        for (std::size_t i = 0; i < samples.size(); ++i)
        {
            values[i] = samples[i].value;
            gradients[i] = samples[i].gradient;
            defined[i] = samples[i].defined ? 1 : 0;
        }
    }
    py::array values_array = owning_array<double>(std::move(values), {m}, true);
    py::array gradients_array = owning_array<double>(std::move(gradients), {m, 3}, true);
    if (!with_defined)
        return py::make_tuple(values_array, gradients_array);
    py::array defined_array =
        owning_array<std::uint8_t>(std::move(defined), {m}, true).attr("view")("bool");
    return py::make_tuple(values_array, gradients_array, defined_array);
}

} // namespace

void bind_implicit(py::module_& m)
{
    py::class_<FieldHandle>(
        m, "Field",
        "A signed scalar field over R^3 (Level 2): negative inside, positive outside, zero on "
        "the surface. Field(surfels) is the point field of oriented surfels (paper §4); "
        "pointform.scene() makes one from the modeling language. Immutable and safe to "
        "evaluate from many threads.")
        .def(py::init([](const std::shared_ptr<Cloud>& surfels, const std::string& fit,
                         bool far_grid, double rim_reach, bool crease_fit, bool noise_scale) {
                 PointFieldOptions options{.fit = parse_plane_fit(fit),
                                           .crease_fit = crease_fit,
                                           .rim_reach = rim_reach,
                                           .noise_scale = noise_scale,
                                           .far_grid = far_grid};
                 std::shared_ptr<const PointField> field;
                 {
                     py::gil_scoped_release release;
                     // The field keeps its own copy (it normalizes the normals).
                     field =
                         std::make_shared<const PointField>(to_point_cloud(surfels->view), options);
                 }
                 return FieldHandle{field, field, "point field (" + fit + ")"};
             }),
             py::arg("surfels"), py::kw_only(), py::arg("fit") = "quadric",
             py::arg("far_grid") = true, py::arg("rim_reach") = PointFieldOptions{}.rim_reach,
             py::arg("crease_fit") = PointFieldOptions{}.crease_fit,
             py::arg("noise_scale") = PointFieldOptions{}.noise_scale,
             "Field(surfels, *, fit='quadric', far_grid=True, rim_reach=0.25, crease_fit=True, "
             "noise_scale=False)\n\n"
             "The signed point field of surfels with normals and radii (pointform.surfels()). "
             "fit: the local surfaces, 'quadric' (default), 'blend', 'centroid' or 'raw' (the "
             "paper's tangent planes). far_grid=False answers deep-inside queries by search "
             "instead of the far grid (exact distances there, slower). rim_reach: how far past a "
             "rim of the samples (a hole's edge, a scan's border) the field reaches, as a "
             "fraction of an automatic influence radius, in (0, 1]; 1 = a whole radius, the "
             "paper's field. crease_fit (quadric only): each sample's surface fitted to its own "
             "face of a crease, and left out of the blend past the crease line (at a concave "
             "crease of a clean cloud, the union of its face and the other face's plane), so "
             "that faces meet there instead of being rounded off or running past it; False = "
             "the principal "
             "normal's quadric everywhere. noise_scale (quadric only, noisy clouds): each "
             "sample's quadric fitted again over coarser subsamples until its residuals are a "
             "fifth of its reach (pointform.reconstruct turns it on where its surface comes out a "
             "sponge). Raises InvalidInput for a cloud without normals or "
             "radii, or non-finite or non-positive ones, or rim_reach out of range.")
        .def("evaluate", &evaluate, py::arg("points"), py::kw_only(), py::arg("defined") = false,
             "evaluate(points, *, defined=False) -> (values, gradients[, defined])\n\n"
             "The field at M points (an M by 3 real array in world units; a float64 "
             "C-contiguous array is used in place, others are converted once): new arrays of "
             "values (M,) float64 and gradients (M, 3) float64, and with defined=True an (M,) "
             "bool array "
             "telling where a sample's influence reaches (elsewhere the value is the signed "
             "distance to the nearest sample's surface). The same values whatever the thread "
             "count. Raises InvalidInput for a wrong shape or non-finite points.")
        .def(
            "bounds",
            [](const FieldHandle& self) {
                const Aabb box = self.field->bounds();
                return py::make_tuple(py::array_t<double>(3, box.min.data()),
                                      py::array_t<double>(3, box.max.data()));
            },
            "bounds() -> (min, max): where the field's surface lies, in world units (infinite "
            "for unbounded scenes).")
        .def_property_readonly(
            "median_radius",
            [](const FieldHandle& self) -> py::object {
                if (!self.point)
                    return py::none();
                return py::float_(self.point->median_radius());
            },
            "The median influence radius of a point field's surfels (None for other fields).")
        .def_property_readonly(
            "strays",
            [](const FieldHandle& self) -> py::object {
                if (!self.point)
                    return py::none();
                const std::span<const std::uint32_t> strays = self.point->stray_samples();
                py::array_t<double> out({static_cast<py::ssize_t>(strays.size()), py::ssize_t{3}});
                auto view = out.mutable_unchecked<2>();
                for (std::size_t k = 0; k < strays.size(); ++k)
                {
                    const Vec3d p = self.point->surfels().world(strays[k]);
                    for (py::ssize_t a = 0; a < 3; ++a)
                        view(static_cast<py::ssize_t>(k), a) = p[a];
                }
                return out;
            },
            "The positions (K by 3, float64) of a point field's stray samples (None for other "
            "fields): samples past 4 times the median reach to the 16th nearest that fill a "
            "volume, stand off their neighbours' plane or are isolated from them, and the groups "
            "of such samples most of which are; marching cubes does not start from them, so "
            "sheets only they hold up are not made (a spray of stray returns round a scan).")
        .def("__repr__",
             [](const FieldHandle& self) { return "<pointform.Field " + self.description + ">"; });

    m.def(
        "scene",
        [](const std::string& expression_or_file, const std::string& fit) {
            auto scans =
                std::make_unique<ScanLoading>(ScanOptions{.field = {.fit = parse_plane_fit(fit)}});
            LoadedScene loaded;
            {
                py::gil_scoped_release release;
                loaded = load_scene_argument(expression_or_file, *scans);
            }
            return FieldHandle{loaded.field, nullptr,
                               "scene (" + std::string(to_string(loaded.kind)) + ")"};
        },
        py::arg("expression_or_file"), py::kw_only(), py::arg("fit") = "quadric",
        "scene(expression_or_file, *, fit='quadric') -> Field\n\n"
        "The field of a scene, as `pointform model` takes it: a scan file (.ply, .xyz, .las, "
        "...; its point field), a scene file, or else a scene expression such as "
        "\"difference(sphere([0,0,0], 1), box([0,0,0], [2,2,2]))\" (see `pointform model "
        "--help`). Raises InvalidInput with the line and column of a malformed scene, IoError "
        "for an unreadable file.");
}

} // namespace pointform::python
