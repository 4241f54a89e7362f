// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/scans.h"
#include "pointform/io/hierarchy.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/reconstruct.h"
#include "pointform/polygonize/scene_mesh.h"
#include "pointform/report/report_json.h"

#include "common.h"

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace pointform::python {

std::size_t Hierarchy::level_index(long long level) const
{
    const auto count = static_cast<long long>(mesh.level_count());
    const long long index = level < 0 ? level + count : level;
    if (index < 0 || index >= count)
        throw InvalidInput("level " + std::to_string(level) +
                           " does not exist: the hierarchy has " + std::to_string(count) +
                           " levels (0 to " + std::to_string(count - 1) + ")");
    return static_cast<std::size_t>(index);
}

const std::vector<Triangle>& hierarchy_faces(Hierarchy& h, std::size_t level)
{
    py::gil_scoped_release release;
    const std::lock_guard lock(h.cache_mutex);
    if (!h.faces[level])
        h.faces[level] = h.mesh.faces(level);
    return *h.faces[level];
}

const std::vector<Vec3d>& hierarchy_world(Hierarchy& h)
{
    py::gil_scoped_release release;
    const std::lock_guard lock(h.cache_mutex);
    if (!h.world)
    {
        const std::span<const Vec3d> positions = h.mesh.positions();
        h.world.emplace(positions.size());
        for (std::size_t v = 0; v < positions.size(); ++v)
            (*h.world)[v] = h.mesh.origin() + positions[v];
    }
    return *h.world;
}

namespace {

std::size_t non_negative(long long value, const char* name)
{
    if (value < 0)
        throw InvalidInput(std::string(name) + " must not be negative, got " +
                           std::to_string(value));
    return static_cast<std::size_t>(value);
}

std::optional<std::size_t> optional_count(const std::optional<long long>& value, const char* name)
{
    if (!value)
        return std::nullopt;
    return non_negative(*value, name);
}

py::dict seconds_dict(const std::vector<std::pair<std::string, double>>& stages)
{
    py::dict out;
    for (const auto& [stage, seconds] : stages)
        out[py::str(stage)] = seconds;
    return out;
}

SemiRegularOptions semi_regular_options(const std::optional<long long>& levels,
                                        const std::optional<long long>& base_faces,
                                        const std::string& stop_rule, const std::string& predictor,
                                        int relax_iterations, const std::string& relaxation,
                                        long long denoise_rounds)
{
    SemiRegularOptions options;
    if (denoise_rounds < 0)
        throw InvalidInput("denoise_rounds must not be negative, got " +
                           std::to_string(denoise_rounds));
    options.denoise_rounds = static_cast<std::size_t>(denoise_rounds); // checked by refine()
    options.levels = optional_count(levels, "levels");
    options.base_faces = optional_count(base_faces, "base_faces");
    options.stop_rule = parse_stop_rule(stop_rule);
    if (options.stop_rule == StopRule::Exact)
        throw InvalidInput("stop_rule: 'exact' is what levels=J asks; expected 'auto' or 'paper'");
    options.predictor = parse_predictor(predictor);
    if (relax_iterations < 0)
        throw InvalidInput("relax_iterations must not be negative, got " +
                           std::to_string(relax_iterations));
    options.relax_iterations = relax_iterations;
    options.relaxation = parse_relaxation(relaxation);
    return options;
}

const SemiRegularOptions default_semi_regular{};
const std::string default_stop_rule(to_string(default_semi_regular.stop_rule));
const std::string default_predictor(to_string(default_semi_regular.predictor));
const std::string default_relaxation(to_string(default_semi_regular.relaxation));

py::array faces_view(std::span<const Triangle> faces, py::handle owner)
{
    return readonly_view(reinterpret_cast<const std::uint32_t*>(faces.data()),
                         {static_cast<py::ssize_t>(faces.size()), 3}, owner);
}

} // namespace

void bind_polygonize(py::module_& m)
{
    py::class_<Hierarchy, std::shared_ptr<Hierarchy>>(
        m, "Hierarchy",
        "A semi-regular multiresolution mesh (Level 3, paper §5.2): a base mesh M0 and its "
        "nested 1-to-4 refinements M1 ... MJ; level i's vertices are a prefix of level i+1's. "
        "Made by reconstruct(), remesh() or load_hierarchy(); `report` says how.")
        .def_property_readonly(
            "level_count", [](const Hierarchy& h) { return h.mesh.level_count(); },
            "Number of levels, J + 1.")
        .def_property_readonly(
            "finest_level", [](const Hierarchy& h) { return h.mesh.finest_level(); },
            "Index J of the finest level.")
        .def(
            "level",
            [](py::object self, long long level) {
                auto& h = self.cast<Hierarchy&>();
                const std::size_t index = h.level_index(level);
                const std::vector<Triangle>& faces = hierarchy_faces(h, index);
                const auto n = static_cast<py::ssize_t>(h.mesh.vertex_count(index));
                const Vec3d* world = h.mesh.origin().isZero() ? h.mesh.positions().data()
                                                              : hierarchy_world(h).data();
                return py::make_tuple(
                    readonly_view(reinterpret_cast<const double*>(world), {n, 3}, self),
                    faces_view(faces, self));
            },
            py::arg("level"),
            "level(i) -> (vertices, faces)\n\n"
            "Level i (negative counts from the finest): vertices an N by 3 float64 array of "
            "world positions and faces an F by 3 uint32 array, both read-only views owned by "
            "the hierarchy (the faces are derived from the base mesh on first use, then kept). "
            "Raises InvalidInput for a level that does not exist.")
        .def(
            "level_mesh",
            [](const Hierarchy& h, long long level) {
                const std::size_t index = h.level_index(level);
                py::gil_scoped_release release;
                return std::make_shared<TriMesh>(h.mesh.level_mesh(index));
            },
            py::arg("level"),
            "level_mesh(i) -> Mesh: level i as the CLI writes it (float32 positions relative "
            "to the origin).")
        .def(
            "vertex_count",
            [](const Hierarchy& h, long long level) {
                return h.mesh.vertex_count(h.level_index(level));
            },
            py::arg("level"), "vertex_count(i) -> int: vertices of level i.")
        .def(
            "face_count",
            [](const Hierarchy& h, long long level) {
                return h.mesh.face_count(h.level_index(level));
            },
            py::arg("level"), "face_count(i) -> int: faces of level i (F0 * 4**i).")
        .def_property_readonly(
            "origin",
            [](py::object self) {
                return readonly_view(self.cast<const Hierarchy&>().mesh.origin().data(), {3}, self);
            },
            "float64 3-vector: world position = origin + position.")
        .def_property_readonly(
            "positions",
            [](py::object self) {
                const auto& h = self.cast<const Hierarchy&>();
                return readonly_view(reinterpret_cast<const double*>(h.mesh.positions().data()),
                                     {static_cast<py::ssize_t>(h.mesh.vertex_count()), 3}, self);
            },
            "Every vertex of every level, level by level: a V by 3 float64 view, relative to "
            "origin.")
        .def_property_readonly(
            "base_faces",
            [](py::object self) {
                return faces_view(self.cast<const Hierarchy&>().mesh.base_faces(), self);
            },
            "F0 by 3 uint32: the base mesh's triangles (a view).")
        .def_property_readonly(
            "level_offsets",
            [](py::object self) {
                const auto offsets = self.cast<const Hierarchy&>().mesh.level_offsets();
                return readonly_view(offsets.data(), {static_cast<py::ssize_t>(offsets.size())},
                                     self);
            },
            "level_count + 1 integers: 0, then each level's vertex count (a view).")
        .def_property_readonly(
            "parent_edges",
            [](py::object self) {
                const auto edges = self.cast<const Hierarchy&>().mesh.parent_edges();
                static_assert(sizeof(ParentEdge) == 2 * sizeof(std::uint32_t));
                return readonly_view(reinterpret_cast<const std::uint32_t*>(edges.data()),
                                     {static_cast<py::ssize_t>(edges.size()), 2}, self);
            },
            "P by 2 uint32: for vertex V0 + k, the edge (a, b) of the level below that it "
            "splits (a view).")
        .def_property_readonly(
            "report", [](const Hierarchy& h) { return h.report; },
            "How it was made: a dict with the figures of the CLI's --json report (levels with "
            "their Hausdorff, mean and robust distances, the base mesh, why refinement stopped, "
            "seconds by stage); None for a hierarchy read from a file.")
        .def(
            "save",
            [](const Hierarchy& h, const std::filesystem::path& path) {
                py::gil_scoped_release release;
                write_hierarchy(path, h.mesh);
            },
            py::arg("path"),
            "save(path): writes the whole hierarchy as a .pfh file (atomically). Raises "
            "IoError.")
        .def("__repr__", [](const Hierarchy& h) {
            return "<pointform.Hierarchy " + std::to_string(h.mesh.level_count()) + " levels, " +
                   std::to_string(h.mesh.face_count(h.mesh.finest_level())) +
                   " faces at the finest>";
        });

    m.def(
        "load_hierarchy",
        [](const std::filesystem::path& path) {
            MultiresMesh mesh;
            {
                py::gil_scoped_release release;
                mesh = read_hierarchy(path);
            }
            return std::make_shared<Hierarchy>(std::move(mesh));
        },
        py::arg("path"),
        "load_hierarchy(path) -> Hierarchy: reads a .pfh file, trusting nothing in it. Raises "
        "IoError for a missing, foreign, truncated or corrupt file.");

    m.def(
        "fill_holes",
        [](const std::shared_ptr<TriMesh>& mesh, double max_share) {
            auto filled = std::make_shared<TriMesh>(*mesh);
            HoleFillStats stats;
            {
                py::gil_scoped_release release;
                stats = fill_mesh_holes(*filled, max_share);
            }
            py::dict report;
            report["holes_filled"] = stats.holes_filled;
            report["hole_vertices"] = stats.hole_vertices;
            report["hole_area_share"] = stats.hole_area_share;
            report["skipped_not_manifold"] = stats.skipped_not_manifold;
            return py::make_tuple(filled, report);
        },
        py::arg("mesh"), py::kw_only(), py::arg("max_share") = ReconstructOptions{}.fill_holes,
        "fill_holes(mesh, *, max_share=0.05) -> (Mesh, dict)\n\n"
        "The mesh with its holes closed, as `pointform mc` closes them (its --fill-holes): each "
        "boundary loop whose rim encloses at most max_share of its component's area gets a "
        "patch faired to continue the surface around it (0 closes none). The mesh's vertices "
        "and faces stay in place, the patches' follow. The dict: holes_filled, hole_vertices, "
        "hole_area_share, skipped_not_manifold (a mesh that is not an oriented 2-manifold is "
        "returned unchanged). Raises InvalidInput for max_share outside [0, 1).");

    m.def(
        "reconstruct",
        [](const std::shared_ptr<Cloud>& cloud, const std::optional<long long>& levels,
           const std::optional<long long>& base_faces, const std::string& stop_rule,
           const std::string& fit, int resolution, double cell,
           const std::optional<long long>& min_component_samples,
           const std::optional<std::filesystem::path>& base_mesh, const py::object& base_triangles,
           long long k, double radius_scale, const std::string& orient,
           const std::string& predictor, int relax_iterations, const std::string& relaxation,
           double fill_holes, double rim_reach, long long denoise_rounds, bool hole_fairing,
           double max_handle, bool face_fit) {
            ReconstructOptions options;
            options.fill_holes = fill_holes; // checked by the base mesh
            options.max_handle = max_handle; // checked by reconstruct()
            options.rim_reach = rim_reach;   // checked by the point field
            options.semi_regular =
                semi_regular_options(levels, base_faces, stop_rule, predictor, relax_iterations,
                                     relaxation, denoise_rounds);
            options.semi_regular.fair_unsupported = hole_fairing;
            options.semi_regular.fit_faces = face_fit;
            options.fit = parse_plane_fit(fit);
            if (resolution != 0 && resolution < 2)
                throw InvalidInput("resolution must be at least 2 (or 0 = automatic), got " +
                                   std::to_string(resolution));
            if (!(cell >= 0.0) || !std::isfinite(cell))
                throw InvalidInput("cell must be positive and finite (or 0 = automatic)");
            if (resolution != 0 && cell != 0.0)
                throw InvalidInput("give resolution or cell, not both");
            options.resolution = resolution;
            options.cell = cell;
            options.min_component_samples =
                optional_count(min_component_samples, "min_component_samples");
            if (base_mesh)
            {
                if (base_faces)
                    throw InvalidInput("give base_mesh or base_faces, not both");
                options.base_mesh = *base_mesh;
            }
            if (!base_triangles.is_none())
            {
                if (base_faces || base_mesh)
                    throw InvalidInput("give base_triangles, base_mesh or base_faces, not two");
                // Over the cloud's own indices, as `pointform view` sends them.
                options.picked_vertices =
                    picked_vertices_from_samples(triangles_from(base_triangles, cloud->view.size()),
                                                 cloud->view, "base_triangles");
            }
            const OrientChoice orientation = parse_orient(orient);
            const SurfelsFromSamplesOptions surfel_options{.k = non_negative(k, "k"),
                                                           .radius_scale = radius_scale,
                                                           .orient = orientation.mode,
                                                           .orient_target = orientation.target};
            SurfelsFromSamples input;
            ReconstructReport report = run_interruptible([&](const ProgressCallback& progress) {
                SurfelsFromSamplesOptions with_progress = surfel_options;
                with_progress.progress = progress;
                input = surfels_from_samples(cloud->view, with_progress);
                options.progress = progress;
                return reconstruct(std::move(input.surfels), options);
            });
            nlohmann::json figures = report_json(report, options);
            figures["estimated_normals"] = input.estimated_normals;
            figures["surfels"] = report_json(input);
            py::dict out = to_python(figures);
            out["stage_seconds"] = seconds_dict(report.stage_seconds);
            return std::make_shared<Hierarchy>(std::move(report.semi_regular.hierarchy), out);
        },
        py::arg("cloud"), py::kw_only(), py::arg("levels") = py::none(),
        py::arg("base_faces") = py::none(), py::arg("stop_rule") = default_stop_rule,
        py::arg("fit") = "quadric", py::arg("resolution") = 0, py::arg("cell") = 0.0,
        py::arg("min_component_samples") = py::none(), py::arg("base_mesh") = py::none(),
        py::arg("base_triangles") = py::none(), py::arg("k") = default_neighbors,
        py::arg("radius_scale") = default_field_radius_scale, py::arg("orient") = "auto",
        py::arg("predictor") = default_predictor,
        py::arg("relax_iterations") = default_semi_regular.relax_iterations,
        py::arg("relaxation") = default_relaxation,
        py::arg("fill_holes") = ReconstructOptions{}.fill_holes,
        py::arg("rim_reach") = ReconstructOptions{}.rim_reach,
        py::arg("denoise_rounds") = static_cast<long long>(RefineOptions{}.denoise_rounds),
        py::arg("hole_fairing") = RefineOptions{}.fair_unsupported,
        py::arg("max_handle") = default_max_handle, py::arg("face_fit") = RefineOptions{}.fit_faces,
        "reconstruct(cloud, *, levels=None, base_faces=None, stop_rule='auto', fit='quadric', "
        "resolution=0, cell=0.0, min_component_samples=None, base_mesh=None, base_triangles=None, "
        "k=16, "
        "radius_scale=1.5, orient='auto', predictor=..., relax_iterations=..., relaxation=..., "
        "fill_holes=0.05, "
        "rim_reach=0.25, denoise_rounds=10, hole_fairing=True, max_handle=6.0, face_fit=True) "
        "-> Hierarchy\n\n"
        "Points to a semi-regular multiresolution mesh (paper §5), as `pointform reconstruct` "
        "does, with the same defaults and the same result: surfels (pointform.surfels() with "
        "k, radius_scale and orient; raw points get normals, points with normals keep them), their "
        "field (fit; rim_reach: how far past a rim of the samples it reaches, in (0, 1] of a "
        "radius), marching cubes (resolution cells along the longest side, or cell size, "
        "or automatic), debris removal, the handles whose loop is at most max_handle median "
        "influence radii long cut and capped (0 keeps them), the automatic base mesh "
        "(base_faces faces) or a picked "
        "one (base_mesh: a file as `reconstruct --base-mesh` reads; base_triangles: an M by 3 "
        "integer array of the cloud's sample indices, as picked in `pointform view`), its holes "
        "enclosing at most fill_holes of their component's area closed (0 keeps them), then "
        "1-to-4 refinement projected onto the field: exactly to "
        "`levels` (0-8), or until stop_rule says so ('auto' or 'paper'); a level where 'auto' "
        "stops on noise is smoothed by denoise_rounds rounds of Taubin's smoothing (0 = none), "
        "and with 'auto' the regions no sample supports (filled holes and their rims) are "
        "faired unless hole_fairing=False (`--no-hole-fairing`); with 'auto' a finest level not "
        "smoothed has its faces fitted to the field in the least-squares sense unless "
        "face_fit=False "
        "(`--no-face-fit`). "
        "Raises InvalidInput "
        "for bad points or options, or work that would not fit in memory.");

    m.def(
        "remesh",
        [](const std::shared_ptr<TriMesh>& mesh, const std::optional<long long>& levels,
           const std::optional<long long>& base_faces, const std::string& stop_rule,
           const std::string& fit, long long samples, std::uint64_t seed, long long k,
           double radius_scale, long long denoise_rounds) {
            RemeshOptions options;
            options.semi_regular = semi_regular_options(
                levels, base_faces, stop_rule, default_predictor,
                default_semi_regular.relax_iterations, default_relaxation, denoise_rounds);
            options.fit = parse_plane_fit(fit);
            options.surfels = {.samples = non_negative(samples, "samples"),
                               .seed = seed,
                               .k = non_negative(k, "k"),
                               .radius_scale = radius_scale};
            RemeshReport report = run_interruptible([&](const ProgressCallback& progress) {
                options.progress = progress;
                return remesh(*mesh, options);
            });
            py::dict out = to_python(report_json(report, options));
            out["stage_seconds"] = seconds_dict(report.stage_seconds);
            return std::make_shared<Hierarchy>(std::move(report.semi_regular.hierarchy), out);
        },
        py::arg("mesh"), py::kw_only(), py::arg("levels") = py::none(),
        py::arg("base_faces") = py::none(), py::arg("stop_rule") = default_stop_rule,
        py::arg("fit") = "quadric", py::arg("samples") = 0,
        py::arg("seed") = SurfelsFromMeshOptions{}.seed, py::arg("k") = default_neighbors,
        py::arg("radius_scale") = default_field_radius_scale,
        py::arg("denoise_rounds") = static_cast<long long>(RefineOptions{}.denoise_rounds),
        "remesh(mesh, *, levels=None, base_faces=None, stop_rule='auto', fit='quadric', "
        "samples=0, seed=1, k=16, radius_scale=1.5, denoise_rounds=10) -> Hierarchy\n\n"
        "An irregular mesh to a semi-regular one (paper §6), as `pointform remesh` does: its "
        "surfels (pointform.surfels_from_mesh()), the mesh simplified to the base mesh "
        "(base_faces; default a quarter of its faces within [200, 20000]), refined on their "
        "field. Raises InvalidInput for a mesh that is not an oriented manifold, or bad "
        "options.");

    m.def(
        "model",
        [](const std::string& expression_or_file, int resolution, double cell,
           const std::optional<std::pair<std::array<double, 3>, std::array<double, 3>>>& bounds,
           const std::string& fit, bool semi_regular, const std::optional<long long>& levels,
           const std::optional<long long>& base_faces) {
            SceneMeshOptions options;
            if (resolution != 0 && resolution < 2)
                throw InvalidInput("resolution must be at least 2 (or 0 = automatic), got " +
                                   std::to_string(resolution));
            if (!(cell >= 0.0) || !std::isfinite(cell))
                throw InvalidInput("cell must be positive and finite (or 0 = automatic)");
            if (resolution != 0 && cell != 0.0)
                throw InvalidInput("give resolution or cell, not both");
            options.grid.resolution = resolution;
            options.grid.cell = cell;
            if (bounds)
            {
                Aabb box;
                box.min = Vec3d(bounds->first[0], bounds->first[1], bounds->first[2]);
                box.max = Vec3d(bounds->second[0], bounds->second[1], bounds->second[2]);
                if (!box.min.allFinite() || !box.max.allFinite() ||
                    !(box.min.array() < box.max.array()).all())
                    throw InvalidInput(
                        "bounds: expected ((xmin, ymin, zmin), (xmax, ymax, "
                        "zmax)), finite, each minimum below its maximum");
                options.grid.bounds = box;
            }
            if (semi_regular)
            {
                options.semi_regular = SemiRegularOptions{};
                options.semi_regular->levels = optional_count(levels, "levels");
                options.semi_regular->base_faces = optional_count(base_faces, "base_faces");
            }
            else if (levels || base_faces)
                throw InvalidInput("levels and base_faces need semi_regular=True");
            const PlaneFit plane_fit = parse_plane_fit(fit);
            return run_interruptible([&](const ProgressCallback& progress) {
                ScanOptions scan_options{.field = {.fit = plane_fit}};
                scan_options.surfels.progress = progress;
                ScanLoading scans(scan_options);
                const LoadedScene scene = load_scene_argument(expression_or_file, scans);
                options.progress = progress;
                SceneMeshReport report = scene_mesh(*scene.field, scans.scans(), options);
                return std::make_shared<TriMesh>(report.semi_regular
                                                     ? std::move(report.finest)
                                                     : std::move(report.marching_cubes.mesh));
            });
        },
        py::arg("expression_or_file"), py::kw_only(), py::arg("resolution") = 0,
        py::arg("cell") = 0.0, py::arg("bounds") = py::none(), py::arg("fit") = "quadric",
        py::arg("semi_regular") = false, py::arg("levels") = py::none(),
        py::arg("base_faces") = py::none(),
        "model(expression_or_file, *, resolution=0, cell=0.0, bounds=None, fit='quadric', "
        "semi_regular=False, levels=None, base_faces=None) -> Mesh\n\n"
        "Polygonizes a scene as `pointform model` does: a scene expression, a scene file or a "
        "scan file (see pointform.scene()), on a grid of `resolution` cells along the box's "
        "longest side (or cell size; default automatic) over `bounds` ((min), (max); default "
        "the scene's), by marching cubes; with semi_regular=True the semi-regular mesh refined "
        "exactly to `levels` (default 2) is returned instead (its finest level). Raises "
        "InvalidInput for a malformed scene (with line and column) or an unbounded one without "
        "bounds.");
}

} // namespace pointform::python
