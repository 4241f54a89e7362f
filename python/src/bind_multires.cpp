// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/multires/details.h"
#include "pointform/multires/edit_file.h"
#include "pointform/report/report_json.h"

#include "common.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>

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

} // namespace

void bind_multires(py::module_& m)
{
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
}

} // namespace pointform::python
