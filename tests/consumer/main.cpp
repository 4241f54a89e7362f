// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Reconstructs a sampled unit sphere through the installed headers and library, writes the
// finest level and reads it back, and checks the result against the sphere.

#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/reconstruct.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

int main(int argc, char** argv)
{
    using namespace pointform;
    PointCloud samples = sample_shape(Shape::Sphere, {.count = 20000});
    samples.normals.clear(); // raw points: normals estimated and oriented
    SurfelsFromSamples surfels = surfels_from_samples(std::move(samples));
    ReconstructOptions options;
    options.semi_regular.levels = 2;
    const ReconstructReport report = reconstruct(std::move(surfels.surfels), options);
    const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
    const TriMesh finest = hierarchy.level_mesh(hierarchy.finest_level());

    const std::filesystem::path out =
        argc > 1 ? std::filesystem::path(argv[1]) : std::filesystem::path("consumer_sphere.ply");
    write_mesh(out, finest);
    const TriMesh back = read_mesh(out);

    double worst = 0.0;
    for (std::size_t v = 0; v < back.vertex_count(); ++v)
        worst = std::max(worst, std::abs(back.vertices.world(v).norm() - 1.0));
    std::printf("levels %zu, faces %zu, vertices %zu, largest |r - 1| %.3g\n",
                hierarchy.level_count(), back.face_count(), back.vertex_count(), worst);
    const bool ok = hierarchy.level_count() == 3 && back.face_count() == finest.face_count() &&
                    back.face_count() == 16 * hierarchy.face_count(0) && worst < 0.01;
    return ok ? 0 : 1;
}
