// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Peer side of run_distance_bench.py: the exact distance from every point of a point file to a
// triangle mesh, as `pointform distance` measures it (TriangleBvh, point to triangle, double
// precision), with the hierarchy's construction and the queries timed apart from reading.
//
//   mesh_distance MESH POINTS OUT.f64
//
// Writes the distances as little-endian float64 in the order of the points and prints
// {"points": N, "triangles": F, "build_s": ..., "query_s": ..., "threads": T} on stdout.

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/spatial/triangle_bvh.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <vector>

int main(int argc, char** argv)
{
    using Clock = std::chrono::steady_clock;
    if (argc != 4)
    {
        std::fprintf(stderr, "usage: mesh_distance MESH POINTS OUT.f64\n");
        return 2;
    }
    try
    {
        const pointform::TriMesh mesh = pointform::read_mesh(argv[1]);
        const pointform::PointCloud points = pointform::read_point_cloud(argv[2]);
        const auto start = Clock::now();
        const pointform::TriangleBvh bvh(mesh);
        const auto built = Clock::now();
        const std::vector<double> distances = pointform::distances_to_mesh(bvh, points);
        const auto done = Clock::now();
        std::ofstream out(argv[3], std::ios::binary);
        out.write(reinterpret_cast<const char*>(distances.data()),
                  static_cast<std::streamsize>(distances.size() * sizeof(double)));
        if (!out)
        {
            std::fprintf(stderr, "mesh_distance: cannot write %s\n", argv[3]);
            return 3;
        }
        std::printf(
            "{\"points\": %zu, \"triangles\": %zu, \"build_s\": %.6f, \"query_s\": %.6f, "
            "\"threads\": %d}\n",
            points.size(), mesh.face_count(), std::chrono::duration<double>(built - start).count(),
            std::chrono::duration<double>(done - built).count(), pointform::thread_count());
    }
    catch (const std::exception& e)
    {
        std::fprintf(stderr, "mesh_distance: %s\n", e.what());
        return 3;
    }
    return 0;
}
