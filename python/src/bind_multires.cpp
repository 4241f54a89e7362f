// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"
#include "pointform/io/textured_export.h"
#include "pointform/multires/details.h"
#include "pointform/multires/edit_file.h"
#include "pointform/multires/export.h"
#include "pointform/multires/texture.h"
#include "pointform/report/report_json.h"

#include "common.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace pointform::python {

namespace {

/// The text of an edit or lattice given as a dict (serialized by Python's json module) or the
/// path of a file (read by the library); `read` parses a path, `parse` text.
template <typename Read, typename Parse>
auto edit_from(const py::object& value, const char* what, Read read, Parse parse)
{
    if (py::isinstance<py::dict>(value))
    {
        const py::object dumps = py::module_::import("json").attr("dumps");
        const auto text = dumps(value).template cast<std::string>();
        py::gil_scoped_release release;
        return parse(text, std::string(what));
    }
    const auto path = value.cast<std::filesystem::path>();
    py::gil_scoped_release release;
    return read(path);
}

/// A level given from Python: not negative.
std::size_t level_index(long long value, const char* name)
{
    if (value < 0)
        throw InvalidInput(std::string(name) + " must not be negative, got " +
                           std::to_string(value));
    return static_cast<std::size_t>(value);
}

/// A textured mesh with its report, as texture() and export_levels() return it.
struct Textured
{
    TexturedMesh mesh;
    py::object report = py::none();
};

/// An H x W x C uint8 view of an image, or None.
py::object image_view(const TextureImage& image, py::handle owner)
{
    if (image.empty())
        return py::none();
    return readonly_view(image.pixels.data(),
                         {image.height, image.width, static_cast<py::ssize_t>(image.channels)},
                         owner);
}

/// An image from an H x W x 3 or 4 uint8 array, or a PNG's path.
TextureImage image_from(const py::object& value)
{
    if (!py::isinstance<py::array>(value))
        return read_png(value.cast<std::filesystem::path>());
    const auto array =
        py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!array || array.ndim() != 3 || (array.shape(2) != 3 && array.shape(2) != 4) ||
        array.shape(0) < 1 || array.shape(1) < 1)
        throw InvalidInput("image: expected an H x W x 3 (or 4) uint8 array or a PNG's path");
    TextureImage image;
    image.height = static_cast<int>(array.shape(0));
    image.width = static_cast<int>(array.shape(1));
    image.channels = static_cast<int>(array.shape(2));
    image.pixels.assign(array.data(), array.data() + array.size());
    return image;
}

/// Writes a textured mesh as `pointform texture` does: .glb whole, or .obj (the finest level of
/// detail) with its .mtl and PNGs beside it.
void save_textured(const TexturedMesh& mesh, const std::filesystem::path& path)
{
    for (const TexturedFile& file : textured_files(path, mesh, mesh.lods.size() - 1))
        write_file_atomically(file.path, file.bytes);
}

} // namespace

void bind_multires(py::module_& m)
{
    py::class_<Textured, std::shared_ptr<Textured>>(
        m, "Textured",
        "A textured mesh whose levels of detail share one vertex buffer (Hierarchy.texture(), "
        "Hierarchy.export_levels()): level i uses the first lod_vertex_counts[i] vertices.")
        .def_property_readonly(
            "positions",
            [](py::object self) {
                return rows3_view<float>(self.cast<const Textured&>().mesh.positions, self);
            },
            "N x 3 float32, relative to origin (a view).")
        .def_property_readonly(
            "origin",
            [](const Textured& t) {
                return py::make_tuple(t.mesh.origin.x(), t.mesh.origin.y(), t.mesh.origin.z());
            },
            "The world origin (x, y, z) of positions.")
        .def_property_readonly(
            "uvs",
            [](py::object self) -> py::object {
                const auto& uvs = self.cast<const Textured&>().mesh.uvs;
                if (uvs.empty())
                    return py::none();
                return readonly_view(reinterpret_cast<const float*>(uvs.data()),
                                     {static_cast<py::ssize_t>(uvs.size()), 2}, self);
            },
            "N x 2 float32 texture coordinates (u right, v down), or None.")
        .def_property_readonly(
            "normals",
            [](py::object self) {
                return rows3_view<float>(self.cast<const Textured&>().mesh.normals, self);
            },
            "N x 3 float32 unit vertex normals of the finest level of detail (a view).")
        .def_property_readonly(
            "lods",
            [](py::object self) {
                py::list out;
                for (const auto& faces : self.cast<const Textured&>().mesh.lods)
                    out.append(readonly_view(reinterpret_cast<const std::uint32_t*>(faces.data()),
                                             {static_cast<py::ssize_t>(faces.size()), 3}, self));
                return out;
            },
            "Per level of detail, F x 3 uint32 faces (views).")
        .def_property_readonly(
            "lod_vertex_counts", [](const Textured& t) { return t.mesh.lod_vertex_counts; },
            "Per level of detail, how many of the first vertices it uses.")
        .def_property_readonly(
            "lod_levels", [](const Textured& t) { return t.mesh.lod_levels; },
            "Per level of detail, the hierarchy level it comes from.")
        .def_property_readonly(
            "base_color",
            [](py::object self) {
                return image_view(self.cast<const Textured&>().mesh.base_color, self);
            },
            "H x W x 3 uint8 colour texture (a view), or None.")
        .def_property_readonly(
            "normal_map",
            [](py::object self) {
                return image_view(self.cast<const Textured&>().mesh.normal_map, self);
            },
            "H x W x 3 uint8 tangent-space normal map (a view), or None.")
        .def_property_readonly(
            "report", [](const Textured& t) { return t.report; },
            "The CLI's --json figures (texture()), or None (export_levels()).")
        .def(
            "save",
            [](const Textured& t, const std::filesystem::path& path) {
                py::gil_scoped_release release;
                save_textured(t.mesh, path);
            },
            py::arg("path"),
            "save(path): OUT.glb (every level of detail, textures embedded) or OUT.obj (the "
            "finest, with OUT.mtl and OUT_color.png / OUT_normal.png beside it).");

    auto hierarchy = py::reinterpret_borrow<py::class_<Hierarchy, std::shared_ptr<Hierarchy>>>(
        m.attr("Hierarchy"));
    hierarchy.def(
        "deform",
        [](const Hierarchy& self, const py::object& edit, const py::object& lattice, bool plain) {
            DeformRequest request;
            if (!edit.is_none() && !lattice.is_none())
                throw InvalidInput("deform: give edit= or lattice=, not both");
            if (!edit.is_none())
                request.edit = edit_from(edit, "edit", read_multires_edit, parse_multires_edit);
            else if (!lattice.is_none())
                request.lattice = edit_from(lattice, "lattice", read_lattice, parse_lattice);
            else
                throw InvalidInput("deform: give edit= (a dict or an edit file) or lattice=");
            if (plain && !request.lattice)
                throw InvalidInput("deform: plain=True needs a lattice");
            request.lattice_mode = plain ? LatticeMode::Plain : LatticeMode::Details;
            MultiresMesh mesh = self.mesh;
            nlohmann::json report;
            {
                py::gil_scoped_release release;
                report = report_json(deform_hierarchy(mesh, request));
            }
            return std::make_shared<Hierarchy>(std::move(mesh), to_python(report));
        },
        py::kw_only(), py::arg("edit") = py::none(), py::arg("lattice") = py::none(),
        py::arg("plain") = false,
        "deform(*, edit=None, lattice=None, plain=False) -> Hierarchy\n\n"
        "Multiresolution editing, as `pointform deform` (docs/deform.md): edit= is a dict "
        "{'level': j, 'handles': [{'vertices': [...], 'translate': [x, y, z]} or {'vertices': "
        "[...], 'matrix': [16 numbers]}], 'region': {'vertices': [...]} or {'ball': {'center': "
        "[...], 'radius': r}} or {'box': {'min': [...], 'max': [...]}}} or the path of such a "
        "JSON file; lattice= a dict or file {'min', 'max', 'degree', 'level', "
        "'control_points'}; plain=True moves every vertex through the lattice. Returns a new "
        "hierarchy (this one is unchanged) whose report is the CLI's --json figures (mode, "
        "deformation per level, the input's details). Raises InvalidInput for a bad edit, "
        "IoError for an unreadable file.");
    hierarchy.def(
        "details",
        [](const Hierarchy& self, double normal_tolerance) {
            nlohmann::json report;
            {
                py::gil_scoped_release release;
                report =
                    report_json(detail_statistics(analyze_details(self.mesh), normal_tolerance),
                                normal_tolerance);
            }
            return to_python(report);
        },
        py::arg("normal_tolerance") = 0.1,
        "details(normal_tolerance=0.1) -> dict: per level 1..J the statistics of the details "
        "(offsets from the predictor in local frames): mean and largest length, mean normal and "
        "tangential parts, and the share that are almost pure normal offsets (tangential part at "
        "most normal_tolerance times the length).");
    hierarchy.def(
        "texture",
        [](const Hierarchy& self, std::optional<long long> level, const py::object& image,
           const py::object& bake_colors, std::optional<long long> normal_map_level, int size) {
            TextureRequest request;
            if (level)
                request.level = level_index(*level, "level");
            if (normal_map_level)
                request.normal_map_level = level_index(*normal_map_level, "normal_map_level");
            if (size != 0 && (size < min_atlas_size || size > max_atlas_size))
                throw InvalidInput("size must be 0 (automatic) or 16 to 16384, got " +
                                   std::to_string(size));
            request.atlas.size = size;
            std::shared_ptr<Cloud> scan;
            if (!image.is_none())
            {
                request.source = TextureRequest::Source::Image;
                request.image = image_from(image);
            }
            else if (!bake_colors.is_none())
            {
                request.source = TextureRequest::Source::BakeColors;
                if (py::isinstance<Cloud>(bake_colors))
                    scan = bake_colors.cast<std::shared_ptr<Cloud>>();
                else
                    scan = std::make_shared<Cloud>(
                        read_point_cloud(bake_colors.cast<std::filesystem::path>()));
            }
            auto out = std::make_shared<Textured>();
            nlohmann::json report;
            {
                py::gil_scoped_release release;
                TextureOutcome outcome =
                    texture_hierarchy(self.mesh, request, scan ? &scan->view : nullptr);
                report = report_json(outcome);
                out->mesh = std::move(outcome.mesh);
            }
            out->report = to_python(report);
            return out;
        },
        py::kw_only(), py::arg("level") = py::none(), py::arg("image") = py::none(),
        py::arg("bake_colors") = py::none(), py::arg("normal_map_level") = py::none(),
        py::arg("size") = 0,
        "texture(*, level=None, image=None, bake_colors=None, normal_map_level=None, size=0) -> "
        "Textured\n\nAs `pointform texture` (docs/texture.md): levels 0..level over the atlas of "
        "the parameterization, with a checker (the default), an image (H x W x 3 uint8 array or "
        "a PNG's path) or the colours of a scan baked in (a PointCloud with colors, or a "
        "path); normal_map_level=j exports level j alone with a normal map of level `level`. "
        "The report is the CLI's --json figures.");
    hierarchy.def(
        "export_levels",
        [](const Hierarchy& self, const std::optional<std::vector<long long>>& levels) {
            std::vector<std::size_t> chosen;
            if (levels)
                for (const long long l : *levels)
                    chosen.push_back(level_index(l, "levels"));
            else
                for (std::size_t l = 0; l < self.mesh.level_count(); ++l)
                    chosen.push_back(l);
            auto out = std::make_shared<Textured>();
            {
                py::gil_scoped_release release;
                out->mesh = level_chain(self.mesh, chosen);
            }
            return out;
        },
        py::arg("levels") = py::none(),
        "export_levels(levels=None) -> Textured: the levels (default all, increasing) as levels "
        "of detail sharing one vertex buffer, no texture, as `pointform export`.");
}

} // namespace pointform::python
