// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/surfels.h"
#include "pointform/report/report_json.h"

#include "common.h"

#include <memory>

namespace pointform::python {

void bind_hermite(py::module_& m)
{
    m.attr("default_neighbors") = default_neighbors;
    m.attr("default_radius_scale") = default_field_radius_scale;

    m.def(
        "surfels",
        [](const std::shared_ptr<Cloud>& cloud, std::size_t k, double radius_scale,
           const std::string& orient, bool reestimate, bool sharp_creases, bool keep_off_surface) {
            const OrientChoice orientation = parse_orient(orient);
            SurfelsFromSamples result = run_interruptible([&](const ProgressCallback& progress) {
                return surfels_from_samples(cloud->view, {.k = k,
                                                          .radius_scale = radius_scale,
                                                          .reestimate = reestimate,
                                                          .orient = orientation.mode,
                                                          .orient_target = orientation.target,
                                                          .sharp_creases = sharp_creases,
                                                          .keep_off_surface = keep_off_surface,
                                                          .progress = progress});
            });
            return py::make_tuple(owned_cloud(std::move(result.surfels)),
                                  to_python(report_json(result)));
        },
        py::arg("cloud"), py::kw_only(), py::arg("k") = default_neighbors,
        py::arg("radius_scale") = default_field_radius_scale, py::arg("orient") = "auto",
        py::arg("reestimate") = false, py::arg("sharp_creases") = false,
        py::arg("keep_off_surface") = false,
        "surfels(cloud, *, k=16, radius_scale=1.5, orient='auto', reestimate=False, "
        "sharp_creases=False, keep_off_surface=False) -> "
        "(PointCloud, dict)\n\n"
        "Samples to the oriented surfels of a field (Level 1 or 2 -> 2, paper §4): raw points "
        "get PCA normals of their k nearest neighbours, oriented consistently in every "
        "connected component (minimum spanning tree; a depth image, a cloud with a `sensor`, "
        "has them face the sensor instead: orient='auto'; or orient as `pointform normals "
        "--orient` spells it: 'mst', 'none', 'flip', 'towards:X,Y,Z' or 'along:X,Y,Z'), and "
        "influence radii (radius_scale times "
        "the distance to the k-th neighbour); points with normals keep them (unless "
        "reestimate) and get radii if they have none. Samples without a usable normal are left "
        "out and counted, and so are samples alone far from the rest (stray returns), samples "
        "standing off the surface of their nearest (stray returns near it; kept with "
        "keep_off_surface) and samples at the very place of an earlier one where radii are "
        "computed. With "
        "sharp_creases, the estimated normals of a clean cloud at its creases are refitted to "
        "each sample's own face (`pointform normals --sharp-creases`). Returns the "
        "surfels (same origin) and a report: estimated_normals, estimated_radii, components, "
        "flipped, crease_refits, towards_sensor, thin_parts, thin_part_turned, degenerate, "
        "unoriented, isolated, off_surface, copies. What "
        "`pointform "
        "reconstruct` does to its input. Raises InvalidInput for a bad orient, fewer than k + 1 "
        "usable "
        "points, all coincident or collinear points, or k < 3 or a radius_scale not positive.");

    m.def(
        "surfels_from_mesh",
        [](const std::shared_ptr<TriMesh>& mesh, std::size_t samples, std::uint64_t seed,
           std::size_t k, double radius_scale) {
            SurfelsFromMesh result;
            {
                py::gil_scoped_release release;
                result = surfels_from_mesh(
                    *mesh,
                    {.samples = samples, .seed = seed, .k = k, .radius_scale = radius_scale});
            }
            py::dict report;
            report["vertex_surfels"] = result.vertex_surfels;
            report["area_surfels"] = result.area_surfels;
            return py::make_tuple(owned_cloud(std::move(result.surfels)), report);
        },
        py::arg("mesh"), py::kw_only(), py::arg("samples") = 0,
        py::arg("seed") = SurfelsFromMeshOptions{}.seed, py::arg("k") = default_neighbors,
        py::arg("radius_scale") = default_field_radius_scale,
        "surfels_from_mesh(mesh, *, samples=0, seed=1, k=16, radius_scale=1.5) -> (PointCloud, "
        "dict)\n\n"
        "A mesh to surfels (remeshing, paper §6): its vertices with area-weighted normals, then "
        "`samples` area-uniform samples (0 = as many as it has vertices) with their triangle's "
        "normal; radii from the k-th neighbour. Report: vertex_surfels, area_surfels.");
}

} // namespace pointform::python
