// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// CGAL peer for the normal-estimation benchmark (bench/peers/run_normals_bench.py).
//
// Licensing: CGAL's Point_set_processing_3 package is GPL-3.0-or-later. This file is ours
// (MIT), but the executable built from it links CGAL and is therefore covered by the GPL. It
// is a stand-alone benchmark peer only: it is never linked into any pointform library or
// tool, and it is never installed.
//
// Usage: cgal_normals IN.xyz OUT.ply [-k K] [--threads T]
//
// Reads "x y z" lines, estimates normals with CGAL::pca_estimate_normals (k neighbours),
// orients them with CGAL::mst_orient_normals (k neighbours, single seed at the highest point,
// oriented towards +Z), and writes a binary little-endian PLY with the input points in input
// order: x y z (double), nx ny nz (float), oriented (uchar, 0 for the points that
// mst_orient_normals left unoriented). Prints one JSON object on stdout:
//   {"tool": "cgal", "points": N, "unoriented": U, "k": K, "concurrency": "...",
//    "threads": T, "timings_s": {"read", "estimate", "orient", "write", "total"}}

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/pca_estimate_normals.h>
#include <CGAL/property_map.h>
#include <CGAL/tags.h>

#ifdef CGAL_LINKED_WITH_TBB
#include <tbb/global_control.h>
#endif

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;

// mst_orient_normals() reorders its range (oriented points first), so every entry carries the
// index of its point in the input file.
using Entry = std::tuple<std::size_t, Point, Vector>;
using PointMap = CGAL::Nth_of_tuple_property_map<1, Entry>;
using NormalMap = CGAL::Nth_of_tuple_property_map<2, Entry>;

#ifdef CGAL_LINKED_WITH_TBB
constexpr const char* concurrency_name = "parallel (TBB)";
#else
constexpr const char* concurrency_name = "sequential (no TBB)";
#endif

struct Arguments
{
    std::string input_path;
    std::string output_path;
    unsigned int k = 16;
    unsigned int threads = 0; // 0: all hardware threads
};

struct Timer
{
    std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

    double lap()
    {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - start).count();
        start = now;
        return seconds;
    }
};

[[noreturn]] void usage_error(const std::string& message)
{
    std::cerr << "cgal_normals: " << message << "\n"
              << "usage: cgal_normals IN.xyz OUT.ply [-k K] [--threads T]\n";
    std::exit(2);
}

unsigned int parse_count(const char* text, const char* name)
{
    char* end = nullptr;
    const unsigned long value = std::strtoul(text, &end, 10);
    if (end == text || *end != '\0' || value == 0 || value > 1'000'000)
    {
        usage_error(std::string("invalid value for ") + name + ": '" + text + "'");
    }
    return static_cast<unsigned int>(value);
}

Arguments parse_arguments(int argc, char** argv)
{
    Arguments args;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i)
    {
        const std::string arg = argv[i];
        if ((arg == "-k" || arg == "--threads") && i + 1 < argc)
        {
            const unsigned int value = parse_count(argv[++i], arg.c_str());
            (arg == "-k" ? args.k : args.threads) = value;
        }
        else if (!arg.empty() && arg[0] == '-')
        {
            usage_error("unknown or incomplete option '" + arg + "'");
        }
        else
        {
            positional.push_back(arg);
        }
    }
    if (positional.size() != 2)
    {
        usage_error("expected IN.xyz and OUT.ply");
    }
    if (args.k < 2)
    {
        usage_error("k must be at least 2");
    }
    args.input_path = positional[0];
    args.output_path = positional[1];
    return args;
}

/// Reads whitespace-separated "x y z" lines; returns entries indexed in file order.
std::vector<Entry> read_xyz(const std::string& path)
{
    std::FILE* file = std::fopen(path.c_str(), "r");
    if (file == nullptr)
    {
        throw std::runtime_error("cannot open '" + path + "'");
    }
    std::unique_ptr<std::FILE, decltype(&std::fclose)> guard(file, &std::fclose);
    std::vector<Entry> entries;
    entries.reserve(1 << 20);
    double x = 0.0;
    double y = 0.0;
    double z = 0.0;
    int fields = 0;
    while ((fields = std::fscanf(file, "%lf %lf %lf", &x, &y, &z)) == 3)
    {
        entries.emplace_back(entries.size(), Point(x, y, z), Vector(0.0, 0.0, 0.0));
    }
    if (fields != EOF)
    {
        throw std::runtime_error("'" + path + "': malformed line after point " +
                                 std::to_string(entries.size()));
    }
    if (entries.size() < 3)
    {
        throw std::runtime_error("'" + path + "': fewer than 3 points");
    }
    return entries;
}

/// Writes the points and normals in input order (entries may be in any order).
void write_ply(const std::string& path, const std::vector<Entry>& entries,
               std::size_t oriented_count)
{
    static_assert(std::endian::native == std::endian::little, "PLY writer assumes little endian");
    constexpr std::size_t record_size = 3 * sizeof(double) + 3 * sizeof(float) + 1;
    const std::size_t n = entries.size();
    std::vector<char> buffer(n * record_size);
    for (std::size_t i = 0; i < n; ++i)
    {
        const auto& [index, p, normal] = entries[i];
        const double xyz[3] = {p.x(), p.y(), p.z()};
        const float nxyz[3] = {static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                               static_cast<float>(normal.z())};
        const unsigned char oriented = i < oriented_count ? 1 : 0;
        char* record = buffer.data() + index * record_size;
        std::memcpy(record, xyz, sizeof(xyz));
        std::memcpy(record + sizeof(xyz), nxyz, sizeof(nxyz));
        record[sizeof(xyz) + sizeof(nxyz)] = static_cast<char>(oriented);
    }
    std::ofstream out(path, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\ncomment cgal_normals benchmark peer\n"
        << "element vertex " << n << "\n"
        << "property double x\nproperty double y\nproperty double z\n"
        << "property float nx\nproperty float ny\nproperty float nz\n"
        << "property uchar oriented\nend_header\n";
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (!out)
    {
        throw std::runtime_error("cannot write '" + path + "'");
    }
}

int run(const Arguments& args)
{
#ifdef CGAL_LINKED_WITH_TBB
    const unsigned int threads =
        args.threads != 0 ? args.threads : std::max(1U, std::thread::hardware_concurrency());
    const tbb::global_control parallelism(tbb::global_control::max_allowed_parallelism, threads);
#else
    const unsigned int threads = 1; // Parallel_if_available_tag is Sequential_tag without TBB
#endif

    Timer timer;
    const Timer total;
    std::vector<Entry> entries = read_xyz(args.input_path);
    const double read_s = timer.lap();

    const auto params = CGAL::parameters::point_map(PointMap()).normal_map(NormalMap());
    CGAL::pca_estimate_normals<CGAL::Parallel_if_available_tag>(entries, args.k, params);
    const double estimate_s = timer.lap();

    const auto first_unoriented = CGAL::mst_orient_normals(entries, args.k, params);
    const double orient_s = timer.lap();
    const auto oriented_count = static_cast<std::size_t>(first_unoriented - entries.begin());

    write_ply(args.output_path, entries, oriented_count);
    const double write_s = timer.lap();
    const double total_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - total.start).count();

    std::printf(
        "{\"tool\": \"cgal\", \"cgal_version\": \"%s\", \"points\": %zu, \"unoriented\": %zu, "
        "\"k\": %u, \"concurrency\": \"%s\", \"threads\": %u, \"timings_s\": {\"read\": %.6f, "
        "\"estimate\": %.6f, \"orient\": %.6f, \"write\": %.6f, \"total\": %.6f}}\n",
        CGAL_VERSION_STR, entries.size(), entries.size() - oriented_count, args.k, concurrency_name,
        threads, read_s, estimate_s, orient_s, write_s, total_s);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    const Arguments args = parse_arguments(argc, argv);
    try
    {
        return run(args);
    }
    catch (const std::exception& error)
    {
        std::cerr << "cgal_normals: " << error.what() << "\n";
        return 1;
    }
}
