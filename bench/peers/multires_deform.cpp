// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// pointform's side of run_deform_bench.py (GitHub issue 16, item 7): multiresolution editing,
// timed apart from reading and writing. Two modes:
//
//   multires_deform resynthesis IN.pfh [--repeat R] [--threads 1,2] [--amplitude A]
//
//     Takes the details of the hierarchy (DetailSynthesizer::analyze), moves every base vertex by
//     a smooth non-rigid map (a twist about the bounding box's vertical axis plus a bend, both of
//     amplitude A, default 0.1: radians of twist over the box's height and a fraction of its
//     diagonal), then times DetailSynthesizer::synthesize(mesh, details, 0), which rebuilds every
//     finer level; best of R runs (default 5) per thread count. Also checks that synthesis of the
//     undeformed base gives the hierarchy back (largest deviation, world units).
//
//   multires_deform edit IN.pfh --level J --center X Y Z --radius R
//       (--handle-vertex V | --handle-point X Y Z [--handle-count K]) --translate DX DY DZ
//       --out PREFIX [--scales 0.25,0.5,0.75,1] [--repeat R] [--handle-radius H] [--threads T]
//
//     The edit of level J: region = the ball (world coordinates), handles = vertex V of level J
//     or the K level-J vertices nearest the point, moved by scale × (DX, DY, DZ) for each scale.
//     Times the MultiresDeformer's construction (analysis of the details, the region, the
//     bi-Laplacian's assembly and factorization) and apply() per target (best of R per target,
//     averaged over the targets). Writes PREFIX_rest.ply (finest level at rest),
//     PREFIX_deformed.ply (finest level after the last target), PREFIX_roi.txt (the finest
//     level's vertices in the same ball), PREFIX_handles.txt (the finest level's handle ids: the
//     level-J handle ids, which are shared across levels, plus, with H > 0, every finest vertex of
//     the region within H of a handle vertex; default H = half the mean length of the level-J
//     edges at the handles) and PREFIX_targets.txt (one translation per line, for the peer).
//
// Prints one JSON object on stdout.

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/multires/deformation.h"
#include "pointform/multires/details.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using pointform::MultiresMesh;
using pointform::Vec3d;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The command line after the mode and the input: --name value... pairs.
class Arguments
{
public:
    Arguments(int argc, char** argv, int first) : argc_(argc), argv_(argv), first_(first) {}

    [[nodiscard]] bool has(const char* name) const { return find(name) >= 0; }

    /// The `count` values after `name`, or an empty vector if the option is absent.
    [[nodiscard]] std::vector<std::string> values(const char* name, int count) const
    {
        const int at = find(name);
        if (at < 0)
            return {};
        if (at + count >= argc_)
            throw std::invalid_argument(std::string(name) + " needs " + std::to_string(count) +
                                        " value(s)");
        return {argv_ + at + 1, argv_ + at + 1 + count};
    }

    [[nodiscard]] double number(const char* name, double fallback) const
    {
        const auto v = values(name, 1);
        return v.empty() ? fallback : std::stod(v[0]);
    }

    [[nodiscard]] Vec3d point(const char* name) const
    {
        const auto v = values(name, 3);
        if (v.empty())
            throw std::invalid_argument(std::string(name) + " is required");
        return {std::stod(v[0]), std::stod(v[1]), std::stod(v[2])};
    }

    [[nodiscard]] std::vector<double> list(const char* name, const char* fallback) const
    {
        const auto v = values(name, 1);
        std::string text = v.empty() ? fallback : v[0];
        std::vector<double> out;
        std::size_t start = 0;
        while (start <= text.size())
        {
            const std::size_t comma = std::min(text.find(',', start), text.size());
            if (comma > start)
                out.push_back(std::stod(text.substr(start, comma - start)));
            start = comma + 1;
        }
        return out;
    }

private:
    int argc_;
    char** argv_;
    int first_;

    [[nodiscard]] int find(const char* name) const
    {
        for (int i = first_; i < argc_; ++i)
            if (std::string(argv_[i]) == name)
                return i;
        return -1;
    }
};

double largest_deviation(const MultiresMesh& a, const MultiresMesh& b)
{
    double largest = 0.0;
    for (std::size_t v = 0; v < a.vertex_count(); ++v)
        largest = std::max(largest, (a.positions()[v] - b.positions()[v]).norm());
    return largest;
}

int resynthesis(const Arguments& args, const char* input)
{
    const auto repeat = static_cast<int>(args.number("--repeat", 5));
    const std::vector<double> threads = args.list("--threads", "1,2");
    const double amplitude = args.number("--amplitude", 0.1);

    auto start = Clock::now();
    const MultiresMesh rest = pointform::read_hierarchy(input);
    const double read_s = seconds_since(start);
    start = Clock::now();
    const pointform::DetailSynthesizer synthesizer(rest);
    const double stencils_s = seconds_since(start);
    start = Clock::now();
    const pointform::MultiresDetails details = synthesizer.analyze(rest);
    const double analyze_s = seconds_since(start);

    // Round trip: the undeformed base gives the hierarchy back.
    MultiresMesh mesh = rest;
    synthesizer.synthesize(mesh, details, 0);
    const double round_trip = largest_deviation(mesh, rest);

    // A smooth non-rigid map of the base: a twist about the vertical axis through the box's
    // centre (angle proportional to height) plus a bend (sideways shift quadratic in height).
    const std::size_t base = rest.vertex_count(0);
    Vec3d low = Vec3d::Constant(std::numeric_limits<double>::max());
    Vec3d high = -low;
    for (std::size_t v = 0; v < base; ++v)
    {
        low = low.cwiseMin(rest.positions()[v]);
        high = high.cwiseMax(rest.positions()[v]);
    }
    const Vec3d centre = 0.5 * (low + high);
    const double height = std::max(high.y() - low.y(), 1e-300);
    const double diagonal = (high - low).norm();
    std::vector<Vec3d> moved_base(base);
    for (std::size_t v = 0; v < base; ++v)
    {
        const Vec3d p = rest.positions()[v] - centre;
        const double s = p.y() / height; // about -0.5 … 0.5
        const double angle = amplitude * s;
        const double c = std::cos(angle);
        const double si = std::sin(angle);
        Vec3d q(c * p.x() + si * p.z(), p.y(), -si * p.x() + c * p.z());
        q.x() += amplitude * diagonal * s * s;
        moved_base[v] = centre + q;
    }
    double base_move = 0.0;
    for (std::size_t v = 0; v < base; ++v)
        base_move = std::max(base_move, (moved_base[v] - rest.positions()[v]).norm());

    const std::size_t resynthesized = rest.vertex_count() - base;
    std::string runs;
    for (const double t : threads)
    {
        pointform::set_thread_count(static_cast<int>(t));
        double best = std::numeric_limits<double>::infinity();
        for (int r = 0; r < std::max(repeat, 1); ++r)
        {
            mesh = rest;
            std::copy(moved_base.begin(), moved_base.end(), mesh.mutable_positions().begin());
            start = Clock::now();
            synthesizer.synthesize(mesh, details, 0);
            best = std::min(best, seconds_since(start));
        }
        char line[256];
        std::snprintf(line, sizeof line,
                      "%s{\"threads\": %d, \"best_s\": %.6e, \"vertices_per_s\": %.6e}",
                      runs.empty() ? "" : ", ", pointform::thread_count(), best,
                      static_cast<double>(resynthesized) / best);
        runs += line;
    }
    // The deformed hierarchy moved its finer levels (a sanity check that synthesis did work).
    const double finest_move = largest_deviation(mesh, rest);
    pointform::set_thread_count(0);

    std::printf(
        "{\"mode\": \"resynthesis\", \"input\": \"%s\", \"levels\": %zu, \"vertices\": %zu, "
        "\"base_vertices\": %zu, \"resynthesized\": %zu, \"predictor\": \"%s\", \"repeat\": %d, "
        "\"read_s\": %.6f, \"stencils_s\": %.6f, \"analyze_s\": %.6f, "
        "\"round_trip_max_error\": %.3e, \"base_max_move\": %.6e, \"finest_max_move\": %.6e, "
        "\"runs\": [%s]}\n",
        input, rest.level_count(), rest.vertex_count(), base, resynthesized,
        std::string(pointform::to_string(rest.predictor())).c_str(), repeat, read_s, stencils_s,
        analyze_s, round_trip, base_move, finest_move, runs.c_str());
    return 0;
}

void write_ids(const std::string& path, const std::vector<std::uint32_t>& ids)
{
    std::ofstream out(path);
    for (const std::uint32_t v : ids)
        out << v << '\n';
    if (!out)
        throw std::runtime_error("cannot write " + path);
}

int edit(const Arguments& args, const char* input)
{
    const auto level = static_cast<std::size_t>(args.number("--level", -1));
    const Vec3d centre = args.point("--center");
    const double radius = args.number("--radius", 0.0);
    const Vec3d translation = args.point("--translate");
    const std::vector<double> scales = args.list("--scales", "0.25,0.5,0.75,1");
    const auto repeat = std::max(1, static_cast<int>(args.number("--repeat", 3)));
    const auto out_prefix = args.values("--out", 1);
    if (out_prefix.empty())
        throw std::invalid_argument("--out PREFIX is required");
    if (scales.empty())
        throw std::invalid_argument("--scales needs at least one value");
    if (args.has("--threads"))
        pointform::set_thread_count(static_cast<int>(args.number("--threads", 0)));

    auto start = Clock::now();
    const MultiresMesh rest = pointform::read_hierarchy(input);
    const double read_s = seconds_since(start);
    if (level >= rest.level_count())
        throw std::invalid_argument("--level " + std::to_string(level) + " does not exist");
    const std::size_t n = rest.vertex_count(level);

    // Handles: one vertex of level j, or the level-j vertices nearest a point.
    std::vector<std::uint32_t> handles;
    if (args.has("--handle-vertex"))
    {
        const auto v = static_cast<std::uint32_t>(args.number("--handle-vertex", 0));
        if (v >= n)
            throw std::invalid_argument("--handle-vertex is not a vertex of the level");
        handles.push_back(v);
    }
    else
    {
        const Vec3d p = args.point("--handle-point");
        const auto k = static_cast<std::size_t>(args.number("--handle-count", 1));
        std::vector<std::uint32_t> order(n);
        std::iota(order.begin(), order.end(), 0U);
        const std::size_t take = std::clamp<std::size_t>(k, 1, n);
        std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(take),
                          order.end(), [&](std::uint32_t a, std::uint32_t b) {
                              const double da = (rest.world(a) - p).squaredNorm();
                              const double db = (rest.world(b) - p).squaredNorm();
                              return da < db || (da == db && a < b);
                          });
        handles.assign(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(take));
    }

    pointform::MultiresEdit edit_spec;
    edit_spec.level = level;
    edit_spec.region = pointform::RegionOfInterest::ball(centre, radius);
    edit_spec.handles.push_back(pointform::DeformHandle::translate(handles, translation));

    start = Clock::now();
    const pointform::MultiresDeformer deformer(rest, edit_spec);
    const double precompute_s = seconds_since(start);

    std::vector<std::vector<Vec3d>> targets;
    for (const double s : scales)
    {
        std::vector<Vec3d> t;
        for (const std::uint32_t v : deformer.handle_vertices())
            t.push_back(rest.world(v) + s * translation);
        targets.push_back(std::move(t));
    }
    MultiresMesh mesh = rest;
    std::vector<double> per_target;
    pointform::DeformReport report;
    for (const auto& t : targets)
    {
        double best = std::numeric_limits<double>::infinity();
        for (int r = 0; r < repeat; ++r)
        {
            start = Clock::now();
            report = deformer.apply(mesh, t);
            best = std::min(best, seconds_since(start));
        }
        per_target.push_back(best);
    }
    const double apply_mean_s = std::accumulate(per_target.begin(), per_target.end(), 0.0) /
                                static_cast<double>(per_target.size());

    // The finest level's region and handles (vertex ids are shared across levels).
    const std::size_t finest = rest.finest_level();
    std::vector<std::uint32_t> roi;
    for (std::uint32_t v = 0; v < rest.vertex_count(); ++v)
        if ((rest.world(v) - centre).norm() <= radius)
            roi.push_back(v);
    double handle_radius = args.number("--handle-radius", -1.0);
    if (handle_radius < 0.0)
    {
        // Half the mean length of the level-j edges at the handle vertices.
        std::vector<std::uint8_t> is_handle(n, 0);
        for (const std::uint32_t v : handles)
            is_handle[v] = 1;
        double sum = 0.0;
        std::size_t count = 0;
        for (const pointform::Triangle& t : rest.faces(level))
            for (int k = 0; k < 3; ++k)
            {
                const std::uint32_t a = t[static_cast<std::size_t>(k)];
                const std::uint32_t b = t[static_cast<std::size_t>((k + 1) % 3)];
                if (is_handle[a] != 0 || is_handle[b] != 0)
                {
                    sum += (rest.world(a) - rest.world(b)).norm();
                    ++count;
                }
            }
        handle_radius = count > 0 ? 0.5 * sum / static_cast<double>(count) : 0.0;
    }
    std::vector<std::uint32_t> fine_handles = handles;
    if (handle_radius > 0.0)
        for (const std::uint32_t v : roi)
            for (const std::uint32_t h : handles)
                if (v != h && (rest.world(v) - rest.world(h)).norm() <= handle_radius)
                {
                    fine_handles.push_back(v);
                    break;
                }
    std::sort(fine_handles.begin(), fine_handles.end());

    start = Clock::now();
    const std::string prefix = out_prefix[0];
    pointform::write_mesh(prefix + "_rest.ply", rest.level_mesh(finest));
    pointform::write_mesh(prefix + "_deformed.ply", mesh.level_mesh(finest));
    write_ids(prefix + "_roi.txt", roi);
    write_ids(prefix + "_handles.txt", fine_handles);
    {
        std::ofstream out(prefix + "_targets.txt");
        out.precision(17);
        for (const double s : scales)
        {
            const Vec3d d = s * translation;
            out << d.x() << ' ' << d.y() << ' ' << d.z() << '\n';
        }
        if (!out)
            throw std::runtime_error("cannot write " + prefix + "_targets.txt");
    }
    const double write_s = seconds_since(start);

    std::string per;
    for (const double s : per_target)
        per += (per.empty() ? "" : ", ") + std::to_string(s);
    std::string handle_list;
    for (const std::uint32_t v : handles)
        handle_list += (handle_list.empty() ? "" : ", ") + std::to_string(v);
    std::size_t moved_finest = 0;
    for (const pointform::LevelMotion& m : report.levels)
        moved_finest += m.moved;
    std::printf(
        "{\"mode\": \"edit\", \"input\": \"%s\", \"levels\": %zu, \"vertices\": %zu, "
        "\"level\": %zu, \"level_vertices\": %zu, \"predictor\": \"%s\", \"threads\": %d, "
        "\"region_vertices\": %zu, \"handle_vertices\": %zu, \"free_vertices\": %zu, "
        "\"unconstrained_vertices\": %zu, \"handles\": [%s], \"finest_roi_vertices\": %zu, "
        "\"finest_handle_vertices\": %zu, \"handle_radius\": %.9g, \"moved_vertices\": %zu, "
        "\"largest_displacement\": %.9g, \"repeat\": %d, \"targets\": %zu, \"read_s\": %.6f, "
        "\"precompute_s\": %.6e, \"apply_s\": [%s], \"apply_mean_s\": %.6e, \"write_s\": %.6f}\n",
        input, rest.level_count(), rest.vertex_count(), level, n,
        std::string(pointform::to_string(rest.predictor())).c_str(), pointform::thread_count(),
        report.region_vertices, report.handle_vertices, report.free_vertices,
        report.unconstrained_vertices, handle_list.c_str(), roi.size(), fine_handles.size(),
        handle_radius, moved_finest, report.largest_displacement, repeat, targets.size(), read_s,
        precompute_s, per.c_str(), apply_mean_s, write_s);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    if (argc < 3)
    {
        std::fprintf(stderr,
                     "usage: multires_deform resynthesis IN.pfh [--repeat R] [--threads 1,2] "
                     "[--amplitude A]\n"
                     "       multires_deform edit IN.pfh --level J --center X Y Z --radius R "
                     "(--handle-vertex V | --handle-point X Y Z [--handle-count K]) "
                     "--translate DX DY DZ --out PREFIX [--scales 0.25,0.5,0.75,1] [--repeat R] "
                     "[--handle-radius H] [--threads T]\n");
        return 2;
    }
    try
    {
        const std::string mode = argv[1];
        const Arguments args(argc, argv, 3);
        if (mode == "resynthesis")
            return resynthesis(args, argv[2]);
        if (mode == "edit")
            return edit(args, argv[2]);
        std::fprintf(stderr, "multires_deform: unknown mode '%s'\n", mode.c_str());
        return 2;
    }
    catch (const std::exception& e)
    {
        std::fprintf(stderr, "multires_deform: %s\n", e.what());
        return 3;
    }
}
