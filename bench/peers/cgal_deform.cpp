// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// CGAL peer for the multiresolution-deformation benchmark (bench/peers/run_deform_bench.py).
//
// Licensing: CGAL's Surface_mesh_deformation package is GPL-3.0-or-later. This file is ours
// (MIT), but the executable built from it links CGAL and is therefore covered by the GPL. It is a
// stand-alone benchmark peer only: it is never linked into any pointform library or tool, and it
// is never installed.
//
// Usage: cgal_deform REST.ply ROI.txt HANDLES.txt TARGETS.txt OUT.ply [--repeat R]
//                    [--iterations N] [--tolerance T] [--alpha A]
//
// Reads the mesh at rest (PLY, vertices in file order), the region of interest and the handle
// vertex ids (one id a line; every handle is also put in the region, as CGAL requires), and the
// translations (one "dx dy dz" a line). Sets up CGAL::Surface_mesh_deformation with SRE_ARAP
// (smoothed rotation enhanced as-rigid-as-possible, CGAL's cotangent weights) on a
// CGAL::Surface_mesh, times preprocess() (the Laplacian and its factorization, Eigen's SparseLU
// by default), then for each translation d times one edit: reset() to the rest positions, each
// handle's target set to its rest position + d, deform() with CGAL's defaults (5 iterations,
// energy tolerance 1e-4) unless --iterations / --tolerance / --alpha (SRE_ARAP's alpha, default
// 0.02) say otherwise; best of R runs per translation. Writes the mesh after the last
// translation as binary PLY (double x y z, the faces of the input) and prints one JSON object on
// stdout.

#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_deformation.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using VertexIndex = Mesh::Vertex_index;
using Deformation =
    CGAL::Surface_mesh_deformation<Mesh, CGAL::Default, CGAL::Default, CGAL::SRE_ARAP>;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::vector<std::uint32_t> read_ids(const char* path, std::size_t vertex_count)
{
    std::ifstream in(path);
    if (!in)
        throw std::runtime_error(std::string("cannot read ") + path);
    std::vector<std::uint32_t> ids;
    std::uint64_t v = 0;
    while (in >> v)
    {
        if (v >= vertex_count)
            throw std::runtime_error(std::string(path) + ": vertex " + std::to_string(v) +
                                     " out of range");
        ids.push_back(static_cast<std::uint32_t>(v));
    }
    return ids;
}

void write_ply(const char* path, const Mesh& mesh)
{
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << mesh.number_of_vertices()
        << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
        << mesh.number_of_faces() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const VertexIndex v : mesh.vertices())
    {
        const Point& p = mesh.point(v);
        const double xyz[3] = {p.x(), p.y(), p.z()};
        out.write(reinterpret_cast<const char*>(xyz), sizeof xyz);
    }
    for (const auto f : mesh.faces())
    {
        const unsigned char three = 3;
        out.write(reinterpret_cast<const char*>(&three), 1);
        for (const VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
        {
            const auto index = static_cast<std::int32_t>(v.idx());
            out.write(reinterpret_cast<const char*>(&index), sizeof index);
        }
    }
    if (!out)
        throw std::runtime_error(std::string("cannot write ") + path);
}

double option(int argc, char** argv, const char* name, double fallback)
{
    for (int i = 6; i + 1 < argc; ++i)
        if (std::string(argv[i]) == name)
            return std::stod(argv[i + 1]);
    return fallback;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 6)
    {
        std::fprintf(stderr,
                     "usage: cgal_deform REST.ply ROI.txt HANDLES.txt TARGETS.txt OUT.ply "
                     "[--repeat R] [--iterations N] [--tolerance T] [--alpha A]\n");
        return 2;
    }
    try
    {
        auto start = Clock::now();
        Mesh mesh;
        {
            std::ifstream in(argv[1], std::ios::binary);
            if (!in || !CGAL::IO::read_PLY(in, mesh) || mesh.is_empty())
                throw std::runtime_error(std::string("cannot read the mesh ") + argv[1]);
        }
        if (!CGAL::is_triangle_mesh(mesh))
            throw std::runtime_error("the mesh is not a triangle mesh");
        const std::vector<std::uint32_t> roi = read_ids(argv[2], mesh.number_of_vertices());
        const std::vector<std::uint32_t> handles = read_ids(argv[3], mesh.number_of_vertices());
        std::vector<std::array<double, 3>> translations;
        {
            std::ifstream in(argv[4]);
            double x = 0.0;
            double y = 0.0;
            double z = 0.0;
            while (in >> x >> y >> z)
                translations.push_back({x, y, z});
            if (translations.empty())
                throw std::runtime_error(std::string("no translations in ") + argv[4]);
        }
        const double read_s = seconds_since(start);
        const int repeat = std::max(1, static_cast<int>(option(argc, argv, "--repeat", 1)));

        start = Clock::now();
        Deformation deformation(mesh);
        const auto iterations = static_cast<unsigned int>(
            option(argc, argv, "--iterations", static_cast<double>(deformation.iterations())));
        const double tolerance = option(argc, argv, "--tolerance", deformation.tolerance());
        const double alpha = option(argc, argv, "--alpha", 0.02);
        deformation.set_iterations(iterations);
        deformation.set_tolerance(tolerance);
        deformation.set_sre_arap_alpha(alpha);
        std::vector<VertexIndex> roi_vertices;
        roi_vertices.reserve(roi.size());
        for (const std::uint32_t v : roi)
            roi_vertices.emplace_back(v);
        deformation.insert_roi_vertices(roi_vertices.begin(), roi_vertices.end());
        std::vector<Point> rest;
        for (const std::uint32_t v : handles)
        {
            deformation.insert_control_vertex(VertexIndex(v));
            rest.push_back(mesh.point(VertexIndex(v)));
        }
        const double setup_s = seconds_since(start);
        start = Clock::now();
        const bool preprocessed = deformation.preprocess();
        const double preprocess_s = seconds_since(start);
        if (!preprocessed)
            throw std::runtime_error("preprocess() failed (the factorization did not succeed)");

        std::vector<double> edit_s;
        std::vector<double> deform_s;
        for (const auto& d : translations)
        {
            double best_edit = std::numeric_limits<double>::infinity();
            double best_deform = std::numeric_limits<double>::infinity();
            for (int r = 0; r < repeat; ++r)
            {
                const auto edit_start = Clock::now();
                deformation.reset();
                for (std::size_t h = 0; h < handles.size(); ++h)
                    deformation.set_target_position(
                        VertexIndex(handles[h]),
                        Point(rest[h].x() + d[0], rest[h].y() + d[1], rest[h].z() + d[2]));
                const auto deform_start = Clock::now();
                deformation.deform();
                best_deform = std::min(best_deform, seconds_since(deform_start));
                best_edit = std::min(best_edit, seconds_since(edit_start));
            }
            edit_s.push_back(best_edit);
            deform_s.push_back(best_deform);
        }
        start = Clock::now();
        write_ply(argv[5], mesh);
        const double write_s = seconds_since(start);

        const auto list = [](const std::vector<double>& values) {
            std::string text;
            for (const double v : values)
                text += (text.empty() ? "" : ", ") + std::to_string(v);
            return text;
        };
        std::size_t control_count = 0;
        for (const std::uint32_t v : handles)
            control_count += deformation.is_control_vertex(VertexIndex(v)) ? 1 : 0;
        const double edit_mean =
            std::accumulate(edit_s.begin(), edit_s.end(), 0.0) / static_cast<double>(edit_s.size());
        std::printf(
            "{\"tool\": \"cgal\", \"algorithm\": \"SRE_ARAP\", \"solver\": \"Eigen::SparseLU "
            "(COLAMD)\", \"vertices\": %zu, \"faces\": %zu, \"roi_vertices\": %zu, "
            "\"handle_vertices\": %zu, \"iterations\": %u, \"tolerance\": %g, \"alpha\": %g, "
            "\"repeat\": %d, \"targets\": %zu, \"read_s\": %.6f, \"setup_s\": %.6e, "
            "\"preprocess_s\": %.6e, \"edit_s\": [%s], \"deform_s\": [%s], \"edit_mean_s\": %.6e, "
            "\"write_s\": %.6f}\n",
            static_cast<std::size_t>(mesh.number_of_vertices()),
            static_cast<std::size_t>(mesh.number_of_faces()), deformation.roi_vertices().size(),
            control_count, iterations, tolerance, alpha, repeat, translations.size(), read_s,
            setup_s, preprocess_s, list(edit_s).c_str(), list(deform_s).c_str(), edit_mean,
            write_s);
    }
    catch (const std::exception& e)
    {
        std::fprintf(stderr, "cgal_deform: %s\n", e.what());
        return 3;
    }
    return 0;
}
