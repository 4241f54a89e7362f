// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// OpenMesh's PropertyT::push_back appends a default-constructed VectorT, which is uninitialised
// by design; GCC flags it inside the inlined std::vector code in sanitizer builds. The pragma
// must come before the first standard header to cover those locations.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "pointform/polygonize/base_mesh.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/metrics/quality.h"
#include "pointform/polygonize/projection.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include "relax.h"
#include "thin_plate.h"

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
// QuadricT.hh uses the vector traits that the mesh header brings.
#include <OpenMesh/Core/Geometry/QuadricT.hh>
#include <OpenMesh/Tools/Decimater/CollapseInfoT.hh>
#include <OpenMesh/Tools/Decimater/Observer.hh>
#include <OpenMesh/Tools/Utils/HeapT.hh>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string_view>
#include <utility>

namespace pointform {

namespace {

// ---------------------------------------------------------------------------------------------
// OpenMesh adapter: a halfedge mesh in double precision, used only inside this file.

struct OmTraits : public OpenMesh::DefaultTraits
{
    using Point = OpenMesh::Vec3d;
    using Normal = OpenMesh::Vec3d;
    VertexAttributes(OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
    FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};
using OmBase = OpenMesh::TriMesh_ArrayKernelT<OmTraits>;

/// The halfedge mesh. It hides TriConnectivity::is_collapse_ok, which the Decimater calls for
/// every candidate collapse, with the same test minus that function's per-call allocations
/// (which made it 70% of the decimation time), the one-rings compared through a mark per vertex.
class OmMesh : public OmBase
{
public:
    /// \brief The link condition: may v0v1 be collapsed (v0 into v1) without changing the
    /// topology? The conditions of OpenMesh's TriConnectivity::is_collapse_ok: the edge and its
    /// vertices exist; neither triangle has its other two edges on the boundary; the opposite
    /// vertices vl and vr differ; the one-rings of v0 and v1 share only vl and vr; an edge between
    /// two boundary vertices is a boundary edge.
    bool is_collapse_ok(HalfedgeHandle v0v1)
    {
        if (status(edge_handle(v0v1)).deleted())
        {
            return false;
        }
        const HalfedgeHandle v1v0 = opposite_halfedge_handle(v0v1);
        const VertexHandle v0 = to_vertex_handle(v1v0);
        const VertexHandle v1 = to_vertex_handle(v0v1);
        if (status(v0).deleted() || status(v1).deleted() || (keep_locked_ && status(v1).locked()))
        {
            return false;
        }
        const auto ear = [this](HalfedgeHandle h) {
            const HalfedgeHandle h1 = next_halfedge_handle(h);
            const HalfedgeHandle h2 = next_halfedge_handle(h1);
            return is_boundary(opposite_halfedge_handle(h1)) &&
                   is_boundary(opposite_halfedge_handle(h2));
        };
        VertexHandle vl;
        VertexHandle vr;
        if (!is_boundary(v0v1))
        {
            vl = to_vertex_handle(next_halfedge_handle(v0v1));
            if (ear(v0v1))
            {
                return false;
            }
        }
        if (!is_boundary(v1v0))
        {
            vr = to_vertex_handle(next_halfedge_handle(v1v0));
            if (ear(v1v0))
            {
                return false;
            }
        }
        if (vl == vr)
        {
            return false;
        }
        // v1's ring marked with a fresh stamp, then v0's looked up in it.
        if (mark_.size() < n_vertices())
            mark_.resize(n_vertices(), 0);
        if (++stamp_ == 0)
        {
            std::fill(mark_.begin(), mark_.end(), 0U);
            stamp_ = 1;
        }
        for (const VertexHandle w : vv_range(v1))
        {
            mark_[static_cast<std::size_t>(w.idx())] = stamp_;
        }
        for (const VertexHandle w : vv_range(v0))
        {
            if (w != vl && w != vr && mark_[static_cast<std::size_t>(w.idx())] == stamp_)
            {
                return false;
            }
        }
        return !(is_boundary(v0) && is_boundary(v1) && !is_boundary(v0v1) && !is_boundary(v1v0));
    }

    /// Refuse collapses onto a locked vertex too (the Decimater refuses those that remove one):
    /// a locked vertex's faces then stay as they are.
    void keep_locked(bool on) { keep_locked_ = on; }
    [[nodiscard]] bool keeps_locked() const { return keep_locked_; }

private:
    std::vector<std::uint32_t> mark_; ///< per vertex: the stamp of the last ring it was in
    std::uint32_t stamp_ = 0;
    bool keep_locked_ = false;
};

Vec3d to_eigen(const OpenMesh::Vec3d& p)
{
    return {p[0], p[1], p[2]};
}

OpenMesh::Vec3d to_om(const Vec3d& p)
{
    return {p.x(), p.y(), p.z()};
}

constexpr double degrees = std::numbers::pi / 180.0;
/// The base mesh's boundary may pass this many times farther from a removed rim vertex on the
/// hole's side than on the mesh's side (BaseMeshOptions::boundary_tolerance): a chord across a
/// hole's rim shrinks the hole, which costs less than growing it, and the rim's vertices are
/// spent where it turns inwards.
constexpr double outward_factor = 4.0;

/// Smallest interior angle of triangle abc, radians; 0 for a degenerate one.
double min_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    return triangle_min_angle(a, b, c);
}

std::array<Vec3d, 3> face_points(const OmMesh& mesh, OmMesh::FaceHandle f)
{
    std::array<Vec3d, 3> p;
    int i = 0;
    for (const auto v : mesh.fv_range(f))
    {
        p[static_cast<std::size_t>(i++)] = to_eigen(mesh.point(v));
    }
    return p;
}

/// Twice the area times the unit normal of triangle abc.
Vec3d area_normal(const std::array<Vec3d, 3>& p)
{
    return (p[1] - p[0]).cross(p[2] - p[0]);
}

/// Forwards the decimater's progress to a ProgressReporter; a cancellation is remembered and
/// rethrown after OpenMesh has returned.
class DecimateObserver final : public OpenMesh::Decimater::Observer
{
public:
    DecimateObserver(ProgressReporter& reporter, std::size_t collapses)
        : Observer(std::max<std::size_t>(collapses / 100, 1)),
          reporter_(reporter),
          collapses_(static_cast<double>(std::max<std::size_t>(collapses, 1)))
    {}
    void notify(std::size_t step) override
    {
        try
        {
            reporter_.update(static_cast<double>(step), collapses_);
        }
        catch (const Cancelled&)
        {
            cancelled_ = true;
        }
    }
    [[nodiscard]] bool abort() const override { return cancelled_; }
    [[nodiscard]] bool cancelled() const { return cancelled_; }

private:
    ProgressReporter& reporter_;
    double collapses_;
    bool cancelled_ = false;
};

/// The decimation's rule that keeps the boundary (the rims of holes) where the intermediate mesh
/// has it. Quadric errors do not see a boundary: removing a rim vertex that lies in the plane
/// of its faces costs nothing, so rims were cut into long chords, and where a chord passed on
/// the mesh's side of the rim the hole grew. Here a collapse along the boundary (a boundary
/// vertex into an interior one is refused before) is refused when the new boundary
/// edge would pass farther than `inward` from a removed rim vertex on the mesh's side (the hole
/// grows), or farther than `outward` on the hole's side (the hole shrinks by a flat piece
/// without samples). Each boundary edge carries the largest deviations of the rim vertices it
/// replaces (bounded by their sum along the chain), which the new edge inherits plus the
/// removed vertex's own.
using CollapseInfo = OpenMesh::Decimater::CollapseInfoT<OmMesh>;

class RimRule
{
public:
    RimRule(OmMesh& mesh, double inward, double outward)
        : mesh_(mesh), inward_(inward), outward_(outward)
    {
        mesh.add_property(deviation_);
        for (const auto e : mesh.edges())
            mesh.property(deviation_, e) = {0.0, 0.0};
    }
    RimRule(const RimRule&) = delete;
    RimRule& operator=(const RimRule&) = delete;
    RimRule(RimRule&&) = delete;
    RimRule& operator=(RimRule&&) = delete;
    ~RimRule() { mesh_.remove_property(deviation_); }

    /// May this collapse be made?
    [[nodiscard]] bool allows(const CollapseInfo& ci) const
    {
        if (!mesh_.is_boundary(ci.v0))
            return true;
        const std::optional<Pending> next = pending(ci);
        return next && next->deviation[0] <= inward_ && next->deviation[1] <= outward_;
    }

    /// Called just before the collapse is made, then after().
    void before(const CollapseInfo& ci)
    {
        pending_ = mesh_.is_boundary(ci.v0) ? pending(ci) : std::nullopt;
    }

    void after(const CollapseInfo& ci)
    {
        if (!pending_)
        {
            return;
        }
        OmMesh& mesh = mesh_;
        const auto h = mesh.find_halfedge(ci.v1, pending_->other);
        if (h.is_valid())
        {
            mesh.property(deviation_, mesh.edge_handle(h)) = pending_->deviation;
        }
        pending_.reset();
    }

private:
    /// Deviations of a boundary edge from the rim vertices it replaces: towards the mesh
    /// (inward) and towards the hole (outward).
    using Deviation = std::array<double, 2>;

    struct Pending
    {
        OmMesh::VertexHandle other; ///< v0's boundary neighbour besides v1
        Deviation deviation{};      ///< of the boundary edge v1–other after the collapse
    };

    /// The deviations of the boundary edge that replaces v0's two boundary edges, or none if
    /// v0 is not a simple boundary vertex collapsing along the boundary.
    [[nodiscard]] std::optional<Pending> pending(const CollapseInfo& ci) const
    {
        const OmMesh& mesh = mesh_;
        const auto out = mesh.halfedge_handle(ci.v0); // a boundary vertex's is on the boundary
        if (!mesh.is_boundary(out))
        {
            return std::nullopt;
        }
        const auto in = mesh.prev_halfedge_handle(out);
        const auto next = mesh.to_vertex_handle(out);
        const auto previous = mesh.from_vertex_handle(in);
        if (next == previous || (ci.v1 != next && ci.v1 != previous))
        {
            return std::nullopt;
        }
        const auto other = ci.v1 == next ? previous : next;
        // The mesh's side at v0: towards the centroids of its faces.
        const Vec3d p0 = to_eigen(ci.p0);
        Vec3d inside = Vec3d::Zero();
        for (const auto f : mesh.vf_range(ci.v0))
        {
            Vec3d centroid = Vec3d::Zero();
            for (const auto w : mesh.fv_range(f))
            {
                centroid += to_eigen(mesh.point(w));
            }
            inside += centroid / 3.0 - p0;
        }
        const Vec3d a = to_eigen(mesh.point(ci.v1));
        const Vec3d b = to_eigen(mesh.point(other));
        const Vec3d ab = b - a;
        const double length2 = ab.squaredNorm();
        const double t = length2 > 0.0 ? std::clamp((p0 - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
        const Vec3d offset = a + t * ab - p0;
        const std::size_t side = offset.dot(inside) > 0.0 ? 0 : 1;
        const Deviation& d_out = mesh.property(deviation_, mesh.edge_handle(out));
        const Deviation& d_in = mesh.property(deviation_, mesh.edge_handle(in));
        Pending result{.other = other,
                       .deviation = {std::max(d_out[0], d_in[0]), std::max(d_out[1], d_in[1])}};
        result.deviation[side] += offset.norm();
        return result;
    }

    OmMesh& mesh_;
    OpenMesh::EPropHandleT<Deviation> deviation_;
    double inward_ = 0.0;
    double outward_ = 0.0;
    std::optional<Pending> pending_;
};

void check_options(const BaseMeshOptions& options)
{
    const auto in_range = [](double value, double low, double high, const std::string& what) {
        if (!(value >= low && value < high))
        {
            throw InvalidInput("base mesh: " + what + " must be in [" + std::to_string(low) + ", " +
                               std::to_string(high) + ") degrees, got " + std::to_string(value));
        }
    };
    in_range(options.min_angle_degrees, 0.0, 60.0, "the minimum-angle target");
    in_range(options.max_normal_deviation_degrees, 1.0, 180.0, "the maximum normal deviation");
    in_range(options.max_flip_dihedral_degrees, 0.0, 90.0, "the maximum flip dihedral angle");
    if (options.boundary_tolerance &&
        !(*options.boundary_tolerance >= 0.0 && std::isfinite(*options.boundary_tolerance)))
    {
        throw InvalidInput("base mesh: the boundary tolerance must be finite and >= 0, got " +
                           std::to_string(*options.boundary_tolerance));
    }
    if (!(options.chord_split_share >= 0.0 && options.chord_split_share <= 0.5))
        throw InvalidInput("base mesh: chord_split_share must be in [0, 0.5], got " +
                           std::to_string(options.chord_split_share));
    if (!(options.min_round_gain >= 0.0 && options.min_round_gain < 1.0))
    {
        throw InvalidInput("base mesh: the least gain of a shape round must be in [0, 1), got " +
                           std::to_string(options.min_round_gain));
    }
    if (options.max_smoothing_rounds < 0)
    {
        throw InvalidInput("base mesh: smoothing rounds must be >= 0, got " +
                           std::to_string(options.max_smoothing_rounds));
    }
    if (!(options.fill_holes >= 0.0 && options.fill_holes < 1.0))
    {
        throw InvalidInput(
            "base mesh: the largest hole to fill must be in [0, 1) of its "
            "component's area, got " +
            std::to_string(options.fill_holes));
    }
}

/// Loops longer than this are never filled: a patch of rings has about n²/12 vertices for a
/// loop of n (80k at this bound), built and faired in time quadratic in the loop.
constexpr std::size_t max_filled_loop = 1000;

/// Rounds of fairing of a patch's inner vertices (Gauss-Seidel: a patch is a few rings deep).
constexpr int fairing_rounds = 200;

/// `loop` resampled at `count` points evenly spaced along its closed polyline, the first at
/// loop[0].
std::vector<Vec3d> resample_loop(const std::vector<Vec3d>& loop, std::size_t count)
{
    const std::size_t n = loop.size();
    std::vector<double> at(n + 1, 0.0);
    for (std::size_t i = 0; i < n; ++i)
        at[i + 1] = at[i] + (loop[(i + 1) % n] - loop[i]).norm();
    std::vector<Vec3d> out(count);
    std::size_t segment = 0;
    for (std::size_t j = 0; j < count; ++j)
    {
        const double s = at[n] * static_cast<double>(j) / static_cast<double>(count);
        while (segment + 1 < n && at[segment + 1] < s)
            ++segment;
        const double length = at[segment + 1] - at[segment];
        const double t = length > 0.0 ? (s - at[segment]) / length : 0.0;
        out[j] = loop[segment] + t * (loop[(segment + 1) % n] - loop[segment]);
    }
    return out;
}

/// A filled hole: its new vertices [first, end).
struct Patch
{
    int first = 0;
    int end = 0;
};

/// Fairs `free` vertices (those of a filled hole) to the smoothest surface that continues the
/// mesh around them: they minimise Σ ‖L x_i‖² over themselves and their neighbours i, with L the
/// uniform Laplacian (the mean of the neighbours minus the vertex) and every other vertex held,
/// so the patch meets its rim with the slope of the ring outside it (thin-plate fairing); or
/// over themselves alone (a membrane) where their rim is flat and the surface around leaves its
/// plane steeply (detail::fill_for_rim(): a face the scanner never saw, whose creases the mesh
/// rounds). Returns false, the vertices untouched, where the system is singular.
bool fair_bilaplacian(OmMesh& mesh, const std::vector<OmMesh::VertexHandle>& free)
{
    std::vector<std::uint32_t> indices(free.size());
    std::vector<char> is_free(mesh.n_vertices(), 0);
    for (std::size_t i = 0; i < free.size(); ++i)
    {
        indices[i] = static_cast<std::uint32_t>(free[i].idx());
        is_free[indices[i]] = 1;
    }
    // The rim (the held vertices next to the free ones) and the held surface's normals there
    // (area-weighted, over the faces with no free vertex).
    std::vector<char> on_rim(mesh.n_vertices(), 0);
    std::vector<Vec3d> rim;
    std::vector<Vec3d> rim_normals;
    for (const auto v : free)
        for (const auto w : mesh.vv_range(v))
        {
            const auto i = static_cast<std::size_t>(w.idx());
            if (is_free[i] != 0 || on_rim[i] != 0)
                continue;
            on_rim[i] = 1;
            Vec3d normal = Vec3d::Zero();
            for (const auto f : mesh.vf_range(w))
            {
                bool held = true;
                for (const auto u : mesh.fv_range(f))
                    held = held && is_free[static_cast<std::size_t>(u.idx())] == 0;
                if (held)
                    normal += area_normal(face_points(mesh, f));
            }
            rim.push_back(to_eigen(mesh.point(w)));
            rim_normals.push_back(normal);
        }
    const std::optional<std::vector<Vec3d>> faired = detail::thin_plate_fairing(
        mesh.n_vertices(), indices,
        [&mesh](std::uint32_t v, const auto& visit) {
            for (const auto w : mesh.vv_range(OmMesh::VertexHandle(static_cast<int>(v))))
                visit(static_cast<std::uint32_t>(w.idx()));
        },
        [&mesh](std::uint32_t v) {
            return to_eigen(mesh.point(OmMesh::VertexHandle(static_cast<int>(v))));
        },
        detail::fill_for_rim(rim, rim_normals));
    if (!faired)
        return false;
    for (std::size_t i = 0; i < free.size(); ++i)
        mesh.set_point(free[i], to_om((*faired)[i]));
    return true;
}

/// Fills the boundary loops of `mesh` that enclose at most `max_share` of their component's
/// area (BaseMeshOptions::fill_holes) with patches of rings at the loop's edge length, then
/// fairs the patches' vertices (a membrane, then thin-plate fairing; the rest of the mesh
/// held). Loops that visit a vertex twice, share one with another loop, or are longer than
/// max_filled_loop, are left open. `filled` marks the new vertices.
void fill_holes(OmMesh& mesh, double max_share, BaseMeshStats& stats, std::vector<char>& filled)
{
    filled.assign(mesh.n_vertices(), 0);
    if (!(max_share > 0.0))
        return;
    // The loops, each as its boundary halfedges in order.
    std::vector<std::vector<OmMesh::HalfedgeHandle>> loops;
    std::vector<char> seen(mesh.n_halfedges(), 0);
    for (const auto start : mesh.halfedges())
    {
        if (!mesh.is_boundary(start) || seen[static_cast<std::size_t>(start.idx())] != 0)
            continue;
        std::vector<OmMesh::HalfedgeHandle> loop;
        auto h = start;
        do
        {
            seen[static_cast<std::size_t>(h.idx())] = 1;
            loop.push_back(h);
            h = mesh.next_halfedge_handle(h);
        } while (h != start);
        loops.push_back(std::move(loop));
    }
    if (loops.empty())
        return;
    // Components of faces and their areas.
    std::vector<int> component(mesh.n_faces(), -1);
    std::vector<double> component_area;
    double total_area = 0.0;
    for (const auto f : mesh.faces())
    {
        if (component[static_cast<std::size_t>(f.idx())] >= 0)
            continue;
        const int id = static_cast<int>(component_area.size());
        component_area.push_back(0.0);
        std::vector<OmMesh::FaceHandle> stack{f};
        component[static_cast<std::size_t>(f.idx())] = id;
        while (!stack.empty())
        {
            const auto g = stack.back();
            stack.pop_back();
            const double area = 0.5 * area_normal(face_points(mesh, g)).norm();
            component_area[static_cast<std::size_t>(id)] += area;
            total_area += area;
            for (const auto h : mesh.ff_range(g))
            {
                if (component[static_cast<std::size_t>(h.idx())] < 0)
                {
                    component[static_cast<std::size_t>(h.idx())] = id;
                    stack.push_back(h);
                }
            }
        }
    }
    double patch_area = 0.0;
    std::vector<Patch> patches;
    for (const auto& loop : loops)
    {
        const std::size_t n = loop.size();
        if (n < 3 || n > max_filled_loop)
            continue;
        std::vector<OmMesh::VertexHandle> rim(n);
        std::vector<Vec3d> p(n);
        for (std::size_t i = 0; i < n; ++i)
        {
            rim[i] = mesh.from_vertex_handle(loop[i]);
            p[i] = to_eigen(mesh.point(rim[i]));
        }
        std::vector<OmMesh::VertexHandle> sorted = rim;
        std::sort(sorted.begin(), sorted.end());
        if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
            continue; // the loop pinches at a vertex
        const bool shared = std::any_of(rim.begin(), rim.end(), [&mesh](auto v) {
            int boundary = 0;
            for (const auto h : mesh.voh_range(v))
                boundary += mesh.is_boundary(h) ? 1 : 0;
            return boundary > 1;
        });
        if (shared)
            continue; // a rim vertex of another loop too
        Vec3d centre = Vec3d::Zero();
        double perimeter = 0.0;
        for (std::size_t i = 0; i < n; ++i)
        {
            centre += p[i];
            perimeter += (p[(i + 1) % n] - p[i]).norm();
        }
        centre /= static_cast<double>(n);
        // The hole's area: its rim's vector area. Where the rim turns round the object that
        // cancels, and the fan of triangles from the rim's centroid does not (for a flat,
        // star-shaped hole the two are equal): a rim whose fan exceeds twice the share is not
        // a hole but a region the scanner missed round a corner, whose patch, rings drawn in
        // to the centroid, would pass through the object. On the sixth simulated fandisk scan
        // (bench/peers/virtual_scan.py, seed 6), where the scanner saw the side walls at
        // grazing angles, a rim of 447 vertices and 45 units along a part of diagonal 7.7 had
        // a vector area of 3.9% of the part's and a fan of 30%, and its patch folded through
        // the part; no filled hole of seeds 1-5 has a fan above 5.4% of the part (an 85-vertex
        // rim of seed 1, 3.0% by its vector area).
        double fan_area = 0.0;
        Vec3d vector_area = Vec3d::Zero();
        for (std::size_t i = 0; i < n; ++i)
        {
            const Vec3d triangle = 0.5 * (p[i] - centre).cross(p[(i + 1) % n] - centre);
            fan_area += triangle.norm();
            vector_area += triangle;
        }
        const auto opposite = mesh.face_handle(mesh.opposite_halfedge_handle(loop[0]));
        const double area_of_component = component_area[static_cast<std::size_t>(
            component[static_cast<std::size_t>(opposite.idx())])];
        if (!(vector_area.norm() <= max_share * area_of_component) ||
            !(fan_area <= 2.0 * max_share * area_of_component))
            continue;
        // Rings from the rim inwards, each with about as many vertices as its length holds
        // edges of the rim's length, and a centre vertex.
        const double edge = perimeter / static_cast<double>(n);
        double radius = 0.0;
        for (const Vec3d& q : p)
            radius += (q - centre).norm();
        radius /= static_cast<double>(n);
        const std::size_t rings = std::max<std::size_t>(
            1, static_cast<std::size_t>(std::llround(radius / std::max(edge, 1e-300))));
        std::vector<OmMesh::VertexHandle> outer = rim;
        std::size_t added = 0;
        const auto first_added = static_cast<int>(mesh.n_vertices());
        bool ok = true;
        const auto add_face = [&](OmMesh::VertexHandle a, OmMesh::VertexHandle b,
                                  OmMesh::VertexHandle c) {
            if (!mesh.add_face(a, b, c).is_valid())
                ok = false;
        };
        if (n == 3)
        {
            add_face(rim[0], rim[1], rim[2]);
        }
        else
        {
            for (std::size_t k = 1; k < rings && ok; ++k)
            {
                const double t = static_cast<double>(k) / static_cast<double>(rings);
                const auto count =
                    static_cast<std::size_t>(std::llround(static_cast<double>(n) * (1.0 - t)));
                if (count < 4)
                    break;
                const std::vector<Vec3d> ring = resample_loop(p, count);
                std::vector<OmMesh::VertexHandle> inner(count);
                for (std::size_t j = 0; j < count; ++j)
                {
                    inner[j] = mesh.add_vertex(to_om(centre + (1.0 - t) * (ring[j] - centre)));
                    ++added;
                }
                // Zip the two rings (outer runs along the loop's halfedges, so its faces
                // continue the mesh's orientation), each advanced when it is behind the other
                // along their common parameter (both start at the loop's first vertex and are
                // spaced evenly): the strip then closes at outer[0]-inner[0] and never joins a
                // vertex to the same one twice, which a greedy choice by diagonal length did
                // when a small inner ring wrapped round at one outer vertex.
                const std::size_t a = outer.size();
                const std::size_t b = inner.size();
                std::size_t i = 0;
                std::size_t j = 0;
                while (i < a || j < b)
                {
                    const bool advance_outer = i < a && (j == b || (i + 1) * b <= (j + 1) * a);
                    if (advance_outer)
                    {
                        add_face(outer[i % a], outer[(i + 1) % a], inner[j % b]);
                        ++i;
                    }
                    else
                    {
                        add_face(inner[j % b], outer[i % a], inner[(j + 1) % b]);
                        ++j;
                    }
                }
                outer = std::move(inner);
            }
            if (ok)
            {
                const auto middle = mesh.add_vertex(to_om(centre));
                ++added;
                for (std::size_t j = 0; j < outer.size() && ok; ++j)
                    add_face(outer[j], outer[(j + 1) % outer.size()], middle);
            }
        }
        if (!ok)
            throw Error("base mesh: filling a hole of " + std::to_string(n) +
                        " rim vertices made a non-manifold patch");
        filled.resize(mesh.n_vertices(), 1);
        if (added > 0)
            patches.push_back(Patch{first_added, static_cast<int>(mesh.n_vertices())});
        stats.hole_vertices += added;
        ++stats.holes_filled;
        patch_area += vector_area.norm();
    }
    stats.hole_area_share = total_area > 0.0 ? patch_area / total_area : 0.0;
    if (stats.holes_filled == 0)
        return;
    // Fairing: each patch to the smoothest surface that continues the mesh around it
    // (fair_bilaplacian()); where its system is singular, each inner vertex to the mean of its
    // neighbours instead (a membrane, Gauss-Seidel), the rest held.
    std::vector<OmMesh::VertexHandle> membrane;
    for (const Patch& patch : patches)
    {
        std::vector<OmMesh::VertexHandle> free;
        for (int v = patch.first; v < patch.end; ++v)
            free.push_back(OmMesh::VertexHandle(v));
        if (!fair_bilaplacian(mesh, free))
            membrane.insert(membrane.end(), free.begin(), free.end());
    }
    for (int round = 0; round < fairing_rounds && !membrane.empty(); ++round)
    {
        for (const auto v : membrane)
        {
            Vec3d sum = Vec3d::Zero();
            int count = 0;
            for (const auto w : mesh.vv_range(v))
            {
                sum += to_eigen(mesh.point(w));
                ++count;
            }
            if (count > 0)
                mesh.set_point(v, to_om(sum / count));
        }
    }
}

/// Adds every vertex of `mesh` (in world coordinates, where the field is evaluated) and every
/// face to the empty `om`, each at its own index; false at the first face OpenMesh refuses
/// (a complex vertex or edge).
bool add_to_openmesh(const TriMesh& mesh, OmMesh& om)
{
    om.reserve(mesh.vertex_count(), mesh.face_count() * 3 / 2, mesh.face_count());
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        om.add_vertex(to_om(mesh.vertices.world(v)));
    for (const Triangle& t : mesh.triangles)
        if (!om.add_face(OmMesh::VertexHandle(static_cast<int>(t[0])),
                         OmMesh::VertexHandle(static_cast<int>(t[1])),
                         OmMesh::VertexHandle(static_cast<int>(t[2])))
                 .is_valid())
            return false;
    return true;
}

/// The mesh in OpenMesh, in world coordinates, without its isolated vertices.
OmMesh to_openmesh(const TriMesh& mesh)
{
    OmMesh om;
    if (!add_to_openmesh(mesh, om))
    {
        throw InvalidInput(
            "base mesh: the intermediate mesh is not a 2-manifold (a face could "
            "not be added to the halfedge mesh)");
    }
    om.delete_isolated_vertices(); // vertices no triangle uses do not belong to the base mesh
    om.garbage_collection();
    return om;
}

/// Passes of edge flips until one flips nothing (at most 10): every interior edge that OpenMesh
/// can flip and whose ends keep their lowest valence (an interior vertex three, a boundary one
/// two) is offered to `flip` with its quad: the edge a-b, its triangles a-b-c and b-a-d (so a
/// flip makes a-d-c and d-b-c). `flip` must be a function of the quad's positions alone, safe to
/// call from several threads. \return the flips made
///
/// Flips change the connectivity only, so `flip` says the same of a quad until one of its
/// triangles changes: each pass first asks it, in parallel, about every edge whose quad is not
/// the one last asked about (all of them in the first pass), then walks the edges in order,
/// asking again only about those whose quad a flip of this pass changed. The flips are those of
/// one walk that asks about every edge.
template <class Decide>
std::size_t flip_passes(OmMesh& mesh, Decide&& flip)
{
    constexpr int max_passes = 10;
    using Quad = std::array<int, 4>;
    struct Decision
    {
        Quad quad{-1, -1, -1, -1}; ///< no edge's
        bool flip = false;
    };
    const std::size_t edges = mesh.n_edges();
    std::vector<Decision> decided(edges);
    const auto interior = [&mesh](OmMesh::EdgeHandle e) {
        return !(mesh.has_edge_status() && mesh.status(e).deleted()) && !mesh.is_boundary(e);
    };
    const auto quad_of = [&mesh](OmMesh::EdgeHandle e) {
        const auto h = mesh.halfedge_handle(e, 0);
        const auto o = mesh.opposite_halfedge_handle(h);
        return Quad{mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx(),
                    mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx(),
                    mesh.to_vertex_handle(mesh.next_halfedge_handle(o)).idx()};
    };
    const auto point = [&mesh](int v) {
        return to_eigen(mesh.point(OmMesh::VertexHandle(v)));
    };
    const auto decide = [&](std::size_t i) {
        const Quad quad = quad_of(OmMesh::EdgeHandle(static_cast<int>(i)));
        if (decided[i].quad != quad)
        {
            decided[i] = {quad,
                          flip(point(quad[0]), point(quad[1]), point(quad[2]), point(quad[3]))};
        }
        return decided[i].flip;
    };
    std::size_t flips = 0;
    for (int pass = 0; pass < max_passes; ++pass)
    {
        parallel_blocks(edges, 1024, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                if (interior(OmMesh::EdgeHandle(static_cast<int>(i))))
                {
                    decide(i);
                }
            }
        });
        std::size_t flips_this_pass = 0;
        for (const auto e : mesh.edges())
        {
            if (!interior(e))
            {
                continue;
            }
            const auto h = mesh.halfedge_handle(e, 0);
            const auto a = mesh.from_vertex_handle(h);
            const auto b = mesh.to_vertex_handle(h);
            const auto lowest = [&mesh](OmMesh::VertexHandle v) {
                return mesh.is_boundary(v) ? 2U : 3U;
            };
            // The wanted flips are few: the geometry decides first, the connectivity's walks
            // around the vertices (the same conditions, so the same flips) only for those.
            if (decide(static_cast<std::size_t>(e.idx())) && mesh.is_flip_ok(e) &&
                mesh.valence(a) > lowest(a) && mesh.valence(b) > lowest(b))
            {
                mesh.flip(e);
                ++flips_this_pass;
            }
        }
        flips += flips_this_pass;
        if (flips_this_pass == 0)
        {
            break;
        }
    }
    return flips;
}

/// Edge flips that raise the smaller minimum angle of an edge's two triangles, where the two
/// triangles' normals differ by at most `max_dihedral` (radians; so a flip does not cut across a
/// crease) and neither new triangle turns further than that from their mean normal.
std::size_t improve_by_flips(OmMesh& mesh, double max_dihedral)
{
    const double flat_cos = std::cos(max_dihedral);
    return flip_passes(
        mesh, [&](const Vec3d& pa, const Vec3d& pb, const Vec3d& pc, const Vec3d& pd) {
            const Vec3d n1 = (pb - pa).cross(pc - pa);
            const Vec3d n2 = (pa - pb).cross(pd - pb);
            const Vec3d m1 = (pd - pa).cross(pc - pa);
            const Vec3d m2 = (pb - pd).cross(pc - pd);
            const double l1 = n1.norm();
            const double l2 = n2.norm();
            const double k1 = m1.norm();
            const double k2 = m2.norm();
            if (l1 == 0.0 || l2 == 0.0 || k1 == 0.0 || k2 == 0.0 || n1.dot(n2) < flat_cos * l1 * l2)
            {
                return false;
            }
            const Vec3d n = (n1 / l1 + n2 / l2).normalized();
            if (m1.dot(n) < flat_cos * k1 || m2.dot(n) < flat_cos * k2)
            {
                return false;
            }
            const double before = std::min(min_angle(pa, pb, pc), min_angle(pb, pa, pd));
            const double after = std::min(min_angle(pa, pd, pc), min_angle(pd, pb, pc));
            return after > before + 1e-9;
        });
}

/// Edge flips across creases: where an edge's two triangles turn by more than `max_dihedral`
/// (radians) from each other, the quad they form is split along the diagonal whose midpoint is
/// nearer the surface, |f| at most half the other's. Decimation and the projection leave edges
/// that cross a crease from one side to the other, with two triangles that straddle it; the
/// crease then runs through the middle of the quad, and the refinement must put the vertex of
/// that edge on the crease's corner, along a direction (the mean of two normals far apart) that
/// has little to do with the surface. The other diagonal joins the vertices nearest the crease
/// and follows it. A flip is made only if both new triangles face the way the field's gradient
/// does at their centroids (no fold) and each end keeps its lowest valence. Flatter pairs are
/// left to improve_by_flips, so the two never undo each other.
std::size_t align_to_creases(OmMesh& mesh, const Field& field, double max_dihedral)
{
    const double flat_cos = std::cos(max_dihedral);
    const auto value = [&field](const Vec3d& p) -> std::optional<double> {
        const FieldSample s = field.evaluate(p);
        if (!s.defined || !std::isfinite(s.value))
        {
            return std::nullopt;
        }
        return std::abs(s.value);
    };
    const auto agrees = [&field](const Vec3d& a, const Vec3d& b, const Vec3d& c) {
        const Vec3d n = (b - a).cross(c - a);
        const FieldSample s = field.evaluate((a + b + c) / 3.0);
        return n.squaredNorm() > 0.0 && s.defined && s.gradient.allFinite() &&
               n.dot(s.gradient) > 0.0;
    };
    return flip_passes(mesh,
                       [&](const Vec3d& pa, const Vec3d& pb, const Vec3d& pc, const Vec3d& pd) {
                           const Vec3d n1 = (pb - pa).cross(pc - pa);
                           const Vec3d n2 = (pa - pb).cross(pd - pb);
                           const double l1 = n1.norm();
                           const double l2 = n2.norm();
                           if (l1 > 0.0 && l2 > 0.0 && n1.dot(n2) >= flat_cos * l1 * l2)
                           {
                               return false; // flat enough: improve_by_flips decides
                           }
                           const std::optional<double> before = value(0.5 * (pa + pb));
                           const std::optional<double> after = value(0.5 * (pc + pd));
                           if (!before || !after || !(*after < 0.5 * *before))
                           {
                               return false;
                           }
                           return agrees(pa, pd, pc) && agrees(pd, pb, pc);
                       });
}

/// Per-vertex state of the shape-improvement and projection stage.
struct VertexState
{
    std::vector<Vec3d> position;
    std::vector<char> on_surface; ///< the current position was projected onto f = 0
    /// The current position was tried as a start of projection and no crossing was found.
    std::vector<char> no_crossing;
};

Vec3d vertex_normal(const OmMesh& mesh, OmMesh::VertexHandle v, const std::vector<Vec3d>& pos)
{
    Vec3d n = Vec3d::Zero();
    for (const auto f : mesh.vf_range(v))
    {
        std::array<Vec3d, 3> p;
        int i = 0;
        for (const auto w : mesh.fv_range(f))
        {
            p[static_cast<std::size_t>(i++)] = pos[static_cast<std::size_t>(w.idx())];
        }
        n += area_normal(p);
    }
    const double length = n.norm();
    return length > 0.0 ? Vec3d(n / length) : Vec3d::Zero();
}

double mean_edge_length(const OmMesh& mesh, OmMesh::VertexHandle v, const std::vector<Vec3d>& pos)
{
    double sum = 0.0;
    int count = 0;
    const Vec3d& p = pos[static_cast<std::size_t>(v.idx())];
    for (const auto w : mesh.vv_range(v))
    {
        sum += (pos[static_cast<std::size_t>(w.idx())] - p).norm();
        ++count;
    }
    return count > 0 ? sum / count : 0.0;
}

/// p moved onto f = 0 along the normalised gradient at p, or along `normal` where the gradient
/// is undefined, within `reach`.
std::optional<Vec3d> project_vertex(const Field& field, const Vec3d& p, const Vec3d& normal,
                                    double reach)
{
    const FieldSample s = field.evaluate(p);
    Vec3d direction = normal;
    if (s.defined && s.gradient.allFinite() && s.gradient.squaredNorm() > 0.0)
    {
        direction = s.gradient.normalized();
    }
    if (direction.squaredNorm() == 0.0 || !(reach > 0.0))
    {
        return std::nullopt;
    }
    return project_to_zero(field, s, p, direction, reach);
}

/// project_spike() looks at vertices of at most this many neighbours: decimation leaves a few of
/// valence 3 and 4 (a tetrahedral dent), and the projection can hold one where the field folds.
/// Taking in every valence moved crease vertices of the simulated fandisk scans of bench/peers
/// (virtual_scan.py, seeds 1-3; their triangles under 20°: 1.37 / 2.16 / 1.28% -> 1.26 / 2.55 /
/// 1.35% at half an edge, 1.18 / 2.60 / 1.16% at a quarter).
constexpr int spike_max_valence = 4;

/// A vertex standing off the surface that its neighbours lie on, a spike or a dent, put back
/// from the neighbours' centroid (its old position, and the gradient there, can hold it where
/// the field folds: at a noisy rim the field may bound a pocket a few spacings thick under the
/// surface, and a vertex decimated onto the pocket's wall projects onto the wall again; on the
/// noisy 100k sphere of bench/peers one of valence 3 stood 0.0165 = 2 spacings inside, the
/// output's largest distance from the truth, 0.45% of the diagonal against marching cubes'
/// 0.39%). nullopt unless the vertex has at most spike_max_valence neighbours, stands farther
/// than a quarter of its mean edge `reach` from the plane of its ring, and
/// detail::project_from_centroid() puts it back.
std::optional<Vec3d> project_spike(const OmMesh& mesh, OmMesh::VertexHandle v, const Field& field,
                                   const std::vector<Vec3d>& pos, double reach)
{
    Vec3d centre = Vec3d::Zero();
    Vec3d newell = Vec3d::Zero();
    int count = 0;
    std::optional<Vec3d> first;
    Vec3d previous = Vec3d::Zero();
    for (const auto w : mesh.vv_range(v))
    {
        const Vec3d& q = pos[static_cast<std::size_t>(w.idx())];
        if (first)
            newell += previous.cross(q);
        else
            first = q;
        previous = q;
        centre += q;
        ++count;
    }
    if (count < 3 || count > spike_max_valence || !(reach > 0.0))
        return std::nullopt;
    newell += previous.cross(*first);
    centre /= count;
    const double length = newell.norm();
    if (!(length > 0.0))
        return std::nullopt;
    const Vec3d ring_normal = newell / length;
    const double off = std::abs((pos[static_cast<std::size_t>(v.idx())] - centre).dot(ring_normal));
    if (!(off > 0.25 * reach))
        return std::nullopt;
    return detail::project_from_centroid(field, centre, off, reach);
}

/// One round: every interior vertex moved tangentially to the average of its neighbours (when
/// `relax`), then every vertex projected onto f = 0 (a spike or dent of low valence from its
/// neighbours' centroid instead, project_spike()); a vertex whose relaxed position cannot be
/// projected tries its old one, and keeps it if that fails too, except a vertex of a filled hole
/// (`filled`), which keeps its relaxed position on the patch. The old position is not tried
/// again where it already found no crossing (VertexState::no_crossing): a filled hole's vertex
/// beyond the field tried its relaxed position in the round before, and would search from it
/// again along a normal turned a little, 40-50 field evaluations a vertex in every round (on
/// simulated fandisk scans, a quarter of the base mesh's evaluations, of which 1 in 25 found
/// the surface). Moves that fold a face (its normal turned by 90° or more, or its area gone)
/// are undone.
void relax_and_project(const OmMesh& mesh, const Field& field, bool relax, VertexState& state,
                       const std::vector<char>& filled)
{
    const std::size_t n = mesh.n_vertices();
    const std::vector<Vec3d>& old = state.position;
    std::vector<Vec3d> next(n);
    std::vector<char> next_on(n, 0);
    std::vector<char> next_none(n, 0);
    parallel_blocks(n, 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto v = OmMesh::VertexHandle(static_cast<int>(i));
            const Vec3d normal = vertex_normal(mesh, v, old);
            const double reach = mean_edge_length(mesh, v, old);
            Vec3d candidate = old[i];
            if (relax && mesh.is_boundary(v))
            {
                // Along the boundary only: to the middle of its two boundary neighbours, in
                // the direction from one to the other (a loop's vertices spread evenly along
                // it, its shape kept).
                const auto out = mesh.halfedge_handle(v);
                const auto in = mesh.prev_halfedge_handle(out);
                if (mesh.is_boundary(out) && mesh.is_boundary(in))
                {
                    const Vec3d& a =
                        old[static_cast<std::size_t>(mesh.from_vertex_handle(in).idx())];
                    const Vec3d& b =
                        old[static_cast<std::size_t>(mesh.to_vertex_handle(out).idx())];
                    const Vec3d chord = b - a;
                    const double length2 = chord.squaredNorm();
                    if (length2 > 0.0)
                        candidate += (0.5 * (a + b) - old[i]).dot(chord) / length2 * chord;
                }
            }
            if (relax && !mesh.is_boundary(v))
            {
                Vec3d centre = Vec3d::Zero();
                int count = 0;
                for (const auto w : mesh.vv_range(v))
                {
                    centre += old[static_cast<std::size_t>(w.idx())];
                    ++count;
                }
                if (count > 0)
                {
                    Vec3d d = centre / count - old[i];
                    d -= d.dot(normal) * normal;
                    candidate += d;
                }
            }
            std::optional<Vec3d> projected;
            if (!mesh.is_boundary(v))
                projected = project_spike(mesh, v, field, old, reach);
            if (!projected)
                projected = project_vertex(field, candidate, normal, reach);
            if (!projected && candidate != old[i] && state.no_crossing[i] == 0)
            {
                projected = project_vertex(field, old[i], normal, reach);
            }
            if (!projected && filled[i] != 0)
            {
                // A filled hole's vertex beyond the field: relaxed on its patch.
                next[i] = candidate;
                next_on[i] = 0;
                next_none[i] = 1;
            }
            else if (projected)
            {
                next[i] = *projected;
                next_on[i] = 1;
            }
            else
            {
                next[i] = old[i];
                next_on[i] = state.on_surface[i];
                next_none[i] = 1;
            }
        }
    });

    // Undo moves that fold a face, until none is left (at worst every vertex of a folding face
    // goes back to its old position, which did not fold).
    for (bool changed = true; changed;)
    {
        changed = false;
        for (const auto f : mesh.faces())
        {
            std::array<std::size_t, 3> ids{};
            int i = 0;
            for (const auto w : mesh.fv_range(f))
            {
                ids[static_cast<std::size_t>(i++)] = static_cast<std::size_t>(w.idx());
            }
            const Vec3d before = area_normal({old[ids[0]], old[ids[1]], old[ids[2]]});
            const Vec3d after = area_normal({next[ids[0]], next[ids[1]], next[ids[2]]});
            if (after.dot(before) > 0.0 && after.norm() > 1e-3 * before.norm())
            {
                continue;
            }
            for (const std::size_t id : ids)
            {
                if (next[id] != old[id])
                {
                    next[id] = old[id];
                    next_on[id] = state.on_surface[id];
                    next_none[id] = state.no_crossing[id];
                    changed = true;
                }
            }
        }
    }
    state.position = std::move(next);
    state.on_surface = std::move(next_on);
    state.no_crossing = std::move(next_none);
}

std::string describe_topology_change(const MeshTopology& before, const MeshTopology& after)
{
    std::string out;
    const auto add = [&out](const std::string& what, auto a, auto b) {
        if (a != b)
        {
            out += (out.empty() ? "" : ", ") + what + " " + std::to_string(a) + " -> " +
                   std::to_string(b);
        }
    };
    add("Euler characteristic", before.euler_characteristic, after.euler_characteristic);
    add("boundary loops", before.boundary_loops, after.boundary_loops);
    add("components", before.components, after.components);
    if (!after.is_oriented_manifold())
    {
        out += std::string(out.empty() ? "" : ", ") + "the base mesh is not an oriented manifold";
    }
    return out;
}

} // namespace

std::size_t fit_base_faces_to_budget(std::size_t target, std::size_t vertex_budget, double fill)
{
    PF_ASSERT(fill > 0.0 && fill <= 1.0);
    const double faces_wanted = 2.0 * fill * static_cast<double>(vertex_budget);
    if (target == 0 || static_cast<double>(target) >= faces_wanted)
        return target;
    // The level count J of log₄(faces_wanted / target), rounded toward the smaller base mesh.
    const double levels = std::ceil(
        std::log(faces_wanted / static_cast<double>(target)) / std::log(4.0) - smaller_base_bias);
    const double fitted = faces_wanted / std::pow(4.0, levels);
    return std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(fitted)));
}

std::size_t default_base_faces(std::size_t faces, std::size_t components, std::size_t share,
                               double coarsening)
{
    const std::size_t lower = std::max<std::size_t>(200, 8 * components);
    const double equivalent = static_cast<double>(faces) * coarsening * coarsening;
    const auto wanted =
        static_cast<std::size_t>(std::min(equivalent / static_cast<double>(share), 1e12));
    return std::min(std::clamp<std::size_t>(wanted, lower, max_default_base_faces), faces);
}

std::size_t default_base_faces(const TriMesh& intermediate, std::size_t share, double coarsening)
{
    PF_ASSERT(share >= 1);
    PF_ASSERT(coarsening >= 1.0);
    return default_base_faces(intermediate.face_count(), analyze_topology(intermediate).components,
                              share, coarsening);
}

MeshTopology check_intermediate_mesh(const TriMesh& intermediate)
{
    if (intermediate.face_count() == 0)
    {
        throw InvalidInput("base mesh: the intermediate mesh has no faces");
    }
    const MeshTopology topology = analyze_topology(intermediate);
    if (!topology.is_oriented_manifold())
    {
        throw InvalidInput("base mesh: the intermediate mesh is not an oriented 2-manifold (" +
                           std::to_string(topology.non_manifold_edges) + " non-manifold edges, " +
                           std::to_string(topology.non_manifold_vertices) +
                           " non-manifold vertices, " + std::to_string(topology.misoriented_edges) +
                           " misoriented edges, " + std::to_string(topology.degenerate_faces) +
                           " degenerate faces)");
    }
    std::vector<std::size_t> valence(intermediate.vertex_count(), 0);
    for (const Triangle& t : intermediate.triangles)
    {
        for (const std::uint32_t v : t)
        {
            ++valence[v];
        }
    }
    const auto highest = std::max_element(valence.begin(), valence.end());
    if (highest != valence.end() && *highest > max_intermediate_valence)
    {
        throw InvalidInput(
            "base mesh: vertex " + std::to_string(highest - valence.begin()) + " is in " +
            std::to_string(*highest) + " triangles, more than the " +
            std::to_string(max_intermediate_valence) +
            " the decimation takes (its cost grows with the cube of a vertex's valence); a "
            "polygon fan-triangulated from one vertex does this: triangulate it another way");
    }
    return topology;
}

namespace {

/// \brief Greedy edge-collapse decimation: Garland and Heckbert's quadric error metric (each
/// vertex's sum of its faces' plane quadrics, weighted by area), every collapse a halfedge
/// collapse of v0 into v1 at v1's position, the cheapest first. A collapse is refused when it
/// would change the topology (the link condition, TriConnectivity's tests), remove a locked
/// vertex (or, with OmMesh::keep_locked(), end on one), take a boundary vertex off the boundary,
/// turn a remaining face's normal by more than the bound (against its normal before that
/// collapse), or move a rim (RimRule).
///
/// This is the algorithm of OpenMesh's DecimaterT with ModQuadricT, ModNormalFlippingT and a
/// boundary module, which it replaced, on the same heap (OpenMesh's HeapT, so ties go the same
/// way), and it makes the same collapses in the same order: a vertex is queued at its cheapest
/// allowed candidate whenever it or a neighbour changes (the quadric errors of other queued
/// vertices go stale as DecimaterT's do), and the candidate's topology is checked again when it
/// reaches the front. What differs is the cost of queueing a vertex: DecimaterT tests every
/// outgoing halfedge (the link condition and up to six face normals each, for every neighbour of
/// every collapse), where here the candidates are sorted by their error first and tested from the
/// cheapest until one is allowed, usually the first. The whole `reconstruct` of the 209k-point
/// depth capture of PCL's table_scene_mug (690k intermediate faces) took 0.80x the wall time in
/// paired runs, a simulated fandisk scan 0.91x, a clean 1M blobby 0.94x, and the outputs of the
/// sampled shapes, scans and captures tried came out byte for byte the same.
class Decimator
{
public:
    Decimator(OmMesh& mesh, const BaseMeshStats& stats, const BaseMeshOptions& options)
        : mesh_(mesh),
          rims_(mesh, stats.boundary_tolerance, outward_factor * stats.boundary_tolerance),
          min_cos_(std::cos(options.max_normal_deviation_degrees * degrees)),
          quadric_(mesh.n_vertices()),
          slot_(mesh.n_vertices()),
          heap_(HeapSlots{&slot_})
    {
        for (const auto f : mesh.faces())
        {
            const std::array<Vec3d, 3> p = face_points(mesh, f);
            Vec3d n = area_normal(p);
            double area = n.norm();
            if (area > static_cast<double>(std::numeric_limits<float>::min()))
            {
                n /= area;
                area *= 0.5;
            }
            OpenMesh::Geometry::Quadricd q(n.x(), n.y(), n.z(), -p[0].dot(n));
            q *= area;
            for (const auto v : mesh.fv_range(f))
                quadric_[static_cast<std::size_t>(v.idx())] += q;
        }
    }

    /// Collapses until `target` faces are left or no collapse is allowed; `observer` (may be
    /// null) sees the count every get_interval() collapses and may stop them.
    void run(std::size_t target, OpenMesh::Decimater::Observer* observer)
    {
        std::size_t faces = mesh_.n_faces();
        heap_.reserve(mesh_.n_vertices());
        for (const auto v : mesh_.vertices())
            if (!mesh_.status(v).deleted())
                enqueue(v);
        std::vector<OmMesh::VertexHandle> support;
        std::size_t collapses = 0;
        while (!heap_.empty() && faces > target)
        {
            const OmMesh::VertexHandle v = heap_.front();
            const OmMesh::HalfedgeHandle h = slot_[static_cast<std::size_t>(v.idx())].target;
            heap_.pop_front();
            const CollapseInfo ci(mesh_, h);
            if (!topology_allows(ci))
                continue; // back in the queue when a neighbour changes
            support.clear();
            for (const auto w : mesh_.vv_range(ci.v0))
                support.push_back(w);
            faces -= mesh_.is_boundary(ci.v0v1) || mesh_.is_boundary(ci.v1v0) ? 1 : 2;
            rims_.before(ci);
            mesh_.collapse(ci.v0v1);
            for (const auto f : mesh_.vf_range(ci.v1))
                mesh_.set_normal(f, mesh_.calc_face_normal(f));
            rims_.after(ci);
            quadric_[static_cast<std::size_t>(ci.v1.idx())] +=
                quadric_[static_cast<std::size_t>(ci.v0.idx())];
            for (const auto w : support)
                enqueue(w);
            ++collapses;
            if (observer != nullptr && collapses % observer->get_interval() == 0)
            {
                observer->notify(collapses);
                if (observer->abort())
                    return;
            }
        }
    }

private:
    struct Candidate
    {
        float priority;
        OmMesh::HalfedgeHandle halfedge;
    };
    /// A vertex's place in the queue: its cheapest allowed candidate and that one's error.
    struct Slot
    {
        float priority = -1.0F;
        OmMesh::HalfedgeHandle target;
        int position = -1; ///< in the heap, or -1
    };
    /// The interface OpenMesh's HeapT needs (as DecimaterT's): the cheapest vertex in front.
    struct HeapSlots
    {
        std::vector<Slot>* slots;
        [[nodiscard]] Slot& at(OmMesh::VertexHandle v) const
        {
            return (*slots)[static_cast<std::size_t>(v.idx())];
        }
        bool less(OmMesh::VertexHandle a, OmMesh::VertexHandle b) const
        {
            return at(a).priority < at(b).priority;
        }
        bool greater(OmMesh::VertexHandle a, OmMesh::VertexHandle b) const
        {
            return at(a).priority > at(b).priority;
        }
        int get_heap_position(OmMesh::VertexHandle v) const { return at(v).position; }
        void set_heap_position(OmMesh::VertexHandle v, int position) const
        {
            at(v).position = position;
        }
    };

    /// v's candidates that pass the cheap tests, with their quadric errors, in halfedge order.
    void gather(OmMesh::VertexHandle v, std::vector<Candidate>& out) const
    {
        out.clear();
        if (mesh_.status(v).locked())
            return;
        const bool boundary = mesh_.is_boundary(v);
        const OpenMesh::Geometry::Quadricd& q0 = quadric_[static_cast<std::size_t>(v.idx())];
        for (const auto h : mesh_.voh_range(v))
        {
            const auto v1 = mesh_.to_vertex_handle(h);
            if (mesh_.status(v1).deleted() || (mesh_.keeps_locked() && mesh_.status(v1).locked()))
                continue;
            if (boundary && !(mesh_.is_boundary(v1) && mesh_.is_boundary(mesh_.edge_handle(h))))
                continue; // a boundary vertex moves only along the boundary
            OpenMesh::Geometry::Quadricd q = q0;
            q += quadric_[static_cast<std::size_t>(v1.idx())];
            const auto error = static_cast<float>(q(mesh_.point(v1)));
            if (error >= 0.0F) // rounding can make it negative, which counts as illegal
                out.push_back({error, h});
        }
    }

    /// Has v exactly three edges?
    bool three_edges(OmMesh::VertexHandle v) const
    {
        int count = 0;
        for (auto h = mesh_.cvoh_begin(v); h.is_valid() && count <= 3; ++h)
            ++count;
        return count == 3;
    }

    /// The topological tests of a candidate besides gather()'s (BaseDecimaterT's).
    bool topology_allows(const CollapseInfo& ci)
    {
        if (!mesh_.is_collapse_ok(ci.v0v1))
            return false;
        if (ci.vl.is_valid() && ci.vr.is_valid() && three_edges(ci.vl) && three_edges(ci.vr) &&
            mesh_.find_halfedge(ci.vl, ci.vr).is_valid())
            return false; // would make a doubled face
        if (mesh_.cw_rotated_halfedge_handle(mesh_.cw_rotated_halfedge_handle(ci.v0v1)) == ci.v0v1)
            return false; // v0 has a single face
        return true;
    }

    /// Every test of a candidate besides gather()'s.
    bool allowed(const CollapseInfo& ci)
    {
        if (!topology_allows(ci) || !rims_.allows(ci))
            return false;
        // No face of v0 left turns by more than the bound.
        mesh_.set_point(ci.v0, ci.p1);
        bool turned = false;
        for (const auto f : mesh_.vf_range(ci.v0))
        {
            if (f != ci.fl && f != ci.fr &&
                OpenMesh::dot(mesh_.normal(f), mesh_.calc_face_normal(f)) < min_cos_)
            {
                turned = true;
                break;
            }
        }
        mesh_.set_point(ci.v0, ci.p0);
        return !turned;
    }

    /// v into the queue at its cheapest allowed candidate, or out of it (DecimaterT's
    /// heap_vertex()).
    void enqueue(OmMesh::VertexHandle v)
    {
        gather(v, scratch_);
        // By error, ties in halfedge order (an insertion sort: a handful of candidates, and
        // std::stable_sort would allocate).
        for (std::size_t i = 1; i < scratch_.size(); ++i)
            for (std::size_t j = i; j > 0 && scratch_[j].priority < scratch_[j - 1].priority; --j)
                std::swap(scratch_[j], scratch_[j - 1]);
        Slot& slot = slot_[static_cast<std::size_t>(v.idx())];
        for (const Candidate& c : scratch_)
        {
            if (allowed(CollapseInfo(mesh_, c.halfedge)))
            {
                slot.target = c.halfedge;
                slot.priority = c.priority;
                if (heap_.is_stored(v))
                    heap_.update(v);
                else
                    heap_.insert(v);
                return;
            }
        }
        if (heap_.is_stored(v))
            heap_.remove(v);
        slot.target = OmMesh::HalfedgeHandle();
        slot.priority = -1.0F;
    }

    OmMesh& mesh_;
    RimRule rims_;
    double min_cos_;
    std::vector<OpenMesh::Geometry::Quadricd> quadric_;
    std::vector<Slot> slot_;
    OpenMesh::Utils::HeapT<OmMesh::VertexHandle, HeapSlots> heap_;
    std::vector<Candidate> scratch_;
};

/// Edge collapses of `mesh` (its face normals requested and up to date) down to `target` faces
/// (Decimator); `observer` (may be null) sees the progress and may stop it.
void collapse_to(OmMesh& mesh, std::size_t target, const BaseMeshStats& stats,
                 const BaseMeshOptions& options, OpenMesh::Decimater::Observer* observer)
{
    Decimator decimator(mesh, stats, options);
    decimator.run(target, observer);
}

/// The `free` vertices of `mesh`, just faired, relaxed along the faired surface
/// (detail::relax_tangentially()), in `position` (by vertex index) and in the mesh.
void relax_faired(OmMesh& mesh, const std::vector<OmMesh::VertexHandle>& free,
                  std::vector<Vec3d>& position)
{
    std::vector<Triangle> faces;
    faces.reserve(mesh.n_faces());
    for (const auto f : mesh.faces())
    {
        Triangle t{};
        std::size_t c = 0;
        for (const auto v : mesh.fv_range(f))
            t[c++] = static_cast<std::uint32_t>(v.idx());
        faces.push_back(t);
    }
    std::vector<std::uint32_t> offsets(mesh.n_vertices() + 1, 0);
    std::vector<std::uint32_t> adjacent;
    for (const auto v : mesh.vertices())
    {
        for (const auto w : mesh.vv_range(v))
            adjacent.push_back(static_cast<std::uint32_t>(w.idx()));
        offsets[static_cast<std::size_t>(v.idx()) + 1] =
            static_cast<std::uint32_t>(adjacent.size());
    }
    std::vector<std::uint32_t> indices;
    for (const auto v : free)
        indices.push_back(static_cast<std::uint32_t>(v.idx()));
    std::sort(indices.begin(), indices.end());
    detail::relax_tangentially(position, faces, offsets, adjacent, indices,
                               detail::faired_relax_rounds);
    for (const std::uint32_t v : indices)
        mesh.set_point(OmMesh::VertexHandle(static_cast<int>(v)), to_om(position[v]));
}

/// The mesh with its holes just filled (fill_holes(); `filled` marks the patches' vertices,
/// `rim` the vertices that were on a boundary before) decimated again to `target` faces (the
/// patches at the mean face area of the rest), by collapses that remove only patch and rim
/// vertices (the others locked). A patch's rings take the edge length of its rim, which the
/// boundary tolerance kept at about the intermediate mesh's: on simulated scans, whose rims are
/// jagged occlusion edges, the patches came out several times as dense as the rest (on three of
/// the fandisk, a quarter of the base vertices for 7% of the area), which spent the vertex
/// budget on holes and made thin triangles where the rims' short edges met the patches'. Once
/// filled, a rim is an inner curve that collapses can coarsen. Measured on those three scans
/// (bench/peers/virtual_scan.py, seeds 1-3; Chamfer to the fandisk in % of the diagonal):
/// 0.306 / 1.162 / 0.869 before, 0.209 / 1.010 / 0.726 after (with the finest level's faired
/// regions relaxed); collapsing every vertex instead of the patches' and rims' only came out
/// worse on all three and on the shipped bunny, whose Chamfer to bun_zipper it raised by 6%.
void recoarsen_filled(OmMesh& mesh, std::size_t target, const BaseMeshStats& stats,
                      const BaseMeshOptions& options, const std::vector<char>& rim,
                      std::vector<char>& filled)
{
    OpenMesh::VPropHandleT<char> mark;
    mesh.add_property(mark);
    for (const auto v : mesh.vertices())
    {
        const auto i = static_cast<std::size_t>(v.idx());
        mesh.property(mark, v) = filled[i];
        if (filled[i] == 0 && (i >= rim.size() || rim[i] == 0))
            mesh.status(v).set_locked(true);
    }
    mesh.update_face_normals();
    collapse_to(mesh, target, stats, options, nullptr);
    for (const auto v : mesh.vertices())
        mesh.status(v).set_locked(false);
    mesh.garbage_collection();
    filled.assign(mesh.n_vertices(), 0);
    for (const auto v : mesh.vertices())
        filled[static_cast<std::size_t>(v.idx())] = mesh.property(mark, v);
    mesh.remove_property(mark);
}

/// The intermediate mesh decimated in blocks at once, towards `target` faces
/// (BaseMeshOptions::block_decimation_faces): its faces in the Morton order of their centroids,
/// cut into decimation_blocks runs of equal count (a fixed number: the result does not depend on
/// the thread count). Each run is decimated on its own with the vertices it shares with another
/// run locked: no collapse removes them or ends on them, so every collapse sees the whole
/// one-ring it changes, as in the whole mesh, and the runs join again where they were cut. A run
/// keeps its faces at the cuts as they are and takes the rest to its share of
/// block_decimation_faces_left(target); the pass over the whole mesh that follows then coarsens
/// the cuts' faces like the others and makes the last collapses. Returns
/// the joined mesh (the intermediate mesh's vertices, the runs' faces), or nothing when a run is
/// not a halfedge mesh of its own (a vertex whose faces in the run OpenMesh cannot link): the
/// caller then decimates the whole mesh at once.
std::optional<TriMesh> decimate_in_blocks(const TriMesh& intermediate, std::size_t target,
                                          const BaseMeshStats& stats,
                                          const BaseMeshOptions& options,
                                          ProgressReporter& reporter)
{
    const std::size_t faces = intermediate.face_count();
    const auto& x = intermediate.vertices.positions;
    std::vector<Vec3f> centroids(faces);
    parallel_blocks(faces, 0, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            const Triangle& t = intermediate.triangles[f];
            centroids[f] = (x[t[0]] + x[t[1]] + x[t[2]]) / 3.0F;
        }
    });
    const std::vector<std::uint32_t> order = spatial_order(centroids);
    std::vector<Vec3f>().swap(centroids);
    const auto run_begin = [&](std::size_t b) {
        return b * faces / decimation_blocks;
    };
    // Each vertex's run, or `shared` when its faces lie in more than one.
    constexpr std::uint32_t unseen = std::numeric_limits<std::uint32_t>::max();
    constexpr std::uint32_t shared = unseen - 1;
    std::vector<std::uint32_t> run_of(intermediate.vertex_count(), unseen);
    for (std::size_t b = 0; b < decimation_blocks; ++b)
        for (std::size_t k = run_begin(b); k < run_begin(b + 1); ++k)
            for (const std::uint32_t v : intermediate.triangles[order[k]])
                run_of[v] =
                    run_of[v] == unseen || run_of[v] == b ? static_cast<std::uint32_t>(b) : shared;
    const double ratio = std::min(
        1.0, static_cast<double>(block_decimation_faces_left(target)) / static_cast<double>(faces));
    std::vector<std::vector<Triangle>> kept(decimation_blocks);
    std::vector<std::uint8_t> linked(decimation_blocks, 1);
    parallel_blocks(
        decimation_blocks, 1,
        [&](std::size_t first, std::size_t last) {
            for (std::size_t b = first; b < last; ++b)
            {
                const std::span<const std::uint32_t> run(order.data() + run_begin(b),
                                                         run_begin(b + 1) - run_begin(b));
                std::vector<std::uint32_t> local; // the run's vertices, ascending
                local.reserve(3 * run.size());
                for (const std::uint32_t f : run)
                    for (const std::uint32_t v : intermediate.triangles[f])
                        local.push_back(v);
                std::sort(local.begin(), local.end());
                local.erase(std::unique(local.begin(), local.end()), local.end());
                // The run as a mesh of its own (its vertices in `local`'s order).
                TriMesh part;
                part.vertices.origin = intermediate.vertices.origin;
                part.vertices.positions.reserve(local.size());
                for (const std::uint32_t v : local)
                    part.vertices.positions.push_back(x[v]);
                part.triangles.reserve(run.size());
                std::size_t at_cuts = 0;
                for (const std::uint32_t f : run)
                {
                    Triangle t = intermediate.triangles[f];
                    at_cuts +=
                        run_of[t[0]] == shared || run_of[t[1]] == shared || run_of[t[2]] == shared
                            ? 1U
                            : 0U;
                    for (std::uint32_t& v : t)
                        v = static_cast<std::uint32_t>(
                            std::lower_bound(local.begin(), local.end(), v) - local.begin());
                    part.triangles.push_back(t);
                }
                OmMesh mesh;
                if (!add_to_openmesh(part, mesh))
                {
                    linked[b] = 0;
                    continue;
                }
                for (std::size_t v = 0; v < local.size(); ++v)
                    if (run_of[local[v]] == shared)
                        mesh.status(OmMesh::VertexHandle(static_cast<int>(v))).set_locked(true);
                mesh.keep_locked(true);
                mesh.request_face_normals();
                mesh.update_face_normals();
                const auto inside = static_cast<double>(run.size() - at_cuts);
                collapse_to(mesh, at_cuts + static_cast<std::size_t>(std::llround(ratio * inside)),
                            stats, options, nullptr);
                for (const auto f : mesh.faces()) // skips the deleted faces
                {
                    Triangle t{};
                    std::size_t k = 0;
                    for (const auto v : mesh.fv_range(f))
                        t[k++] = local[static_cast<std::size_t>(v.idx())];
                    kept[b].push_back(t);
                }
            }
        },
        &reporter);
    if (std::find(linked.begin(), linked.end(), 0) != linked.end())
        return std::nullopt;
    TriMesh joined;
    joined.vertices = intermediate.vertices;
    for (const auto& run : kept)
        joined.triangles.insert(joined.triangles.end(), run.begin(), run.end());
    return joined;
}

/// The value at index size / 2 of `values` in order (the upper median). \pre !values.empty()
double middle_value(std::vector<double> values)
{
    PF_ASSERT(!values.empty());
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

/// split_long_chords(): an edge is split when it is longer than this many times the median
/// edge ...
constexpr double chord_split_length = 1.5;
/// ... one of its faces' centroids lies farther than this many times the median face's from
/// f = 0 ...
constexpr double chord_split_error = 2.0;
/// ... and its two faces meet at a dihedral angle under this, degrees (a smooth, curved spot,
/// not a crease, whose faces the shape rounds align with it).
constexpr double chord_split_dihedral = 10.0;
/// A split must leave each of its new triangles an angle of at least this, degrees, or at least
/// the smallest angle of the two faces it splits.
constexpr double chord_split_min_angle = 20.0;

/// Splits the base mesh's longest chords (BaseMeshOptions::chord_split_share): the edges longer
/// than chord_split_length times the median edge, across which the faces meet at less than
/// chord_split_dihedral and next to a face whose centroid lies more than chord_split_error
/// times the median face's off f = 0, the farthest first. Each edge's midpoint is projected
/// onto f = 0 (project_vertex()) and the edge split there when the projection succeeds and the
/// new triangles keep their shape (chord_split_min_angle) and their side. Returns the splits;
/// the new vertices come last, in `state` (on the surface), `filled` (0) and `start` (the
/// midpoint, for the report's largest move).
std::size_t split_long_chords(OmMesh& mesh, const Field& field, double max_share,
                              VertexState& state, std::vector<char>& filled,
                              std::vector<Vec3d>& start)
{
    const std::size_t faces = mesh.n_faces();
    const auto cap = static_cast<std::size_t>(max_share * static_cast<double>(faces));
    if (cap == 0 || faces == 0)
        return 0;
    const auto at = [&](OmMesh::VertexHandle v) -> const Vec3d& {
        return state.position[static_cast<std::size_t>(v.idx())];
    };
    // Each face's chord error: |f| at its centroid (0 where the field is undefined).
    std::vector<double> error(faces, 0.0);
    parallel_blocks(faces, 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const OmMesh::FaceHandle f(static_cast<int>(i));
            Vec3d centre = Vec3d::Zero();
            for (const auto v : mesh.fv_range(f))
                centre += at(v);
            const FieldSample sample = field.evaluate(centre / 3.0);
            if (sample.defined && std::isfinite(sample.value))
                error[i] = std::abs(sample.value);
        }
    });
    const double error_limit = chord_split_error * middle_value(error);
    std::vector<double> lengths;
    lengths.reserve(mesh.n_edges());
    for (const auto e : mesh.edges())
        lengths.push_back((at(mesh.to_vertex_handle(mesh.halfedge_handle(e, 0))) -
                           at(mesh.from_vertex_handle(mesh.halfedge_handle(e, 0))))
                              .norm());
    const double length_limit = chord_split_length * middle_value(lengths);
    const double cos_dihedral = std::cos(chord_split_dihedral * degrees);
    const auto normal_of = [&](OmMesh::FaceHandle f) {
        std::array<Vec3d, 3> p;
        int i = 0;
        for (const auto v : mesh.fv_range(f))
            p[static_cast<std::size_t>(i++)] = at(v);
        return area_normal(p);
    };
    // Candidates: (error, edge), the largest error first, ties by edge index.
    std::vector<std::pair<double, int>> candidates;
    for (const auto e : mesh.edges())
    {
        const auto h0 = mesh.halfedge_handle(e, 0);
        const auto h1 = mesh.halfedge_handle(e, 1);
        if (mesh.is_boundary(e) || !(lengths[static_cast<std::size_t>(e.idx())] > length_limit))
            continue;
        const auto f0 = mesh.face_handle(h0);
        const auto f1 = mesh.face_handle(h1);
        const double worst = std::max(error[static_cast<std::size_t>(f0.idx())],
                                      error[static_cast<std::size_t>(f1.idx())]);
        if (!(worst > error_limit))
            continue;
        const Vec3d n0 = normal_of(f0);
        const Vec3d n1 = normal_of(f1);
        if (!(n0.dot(n1) > cos_dihedral * n0.norm() * n1.norm()))
            continue;
        candidates.emplace_back(worst, e.idx());
    }
    std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    std::size_t splits = 0;
    for (const auto& [worst, index] : candidates)
    {
        if (splits >= cap)
            break;
        const OmMesh::EdgeHandle e(index);
        const auto h = mesh.halfedge_handle(e, 0);
        const auto a = mesh.from_vertex_handle(h);
        const auto b = mesh.to_vertex_handle(h);
        if (state.on_surface[static_cast<std::size_t>(a.idx())] == 0 ||
            state.on_surface[static_cast<std::size_t>(b.idx())] == 0)
            continue;
        // The two faces as (a, b, c) and (b, a, d), each in its own orientation.
        const auto c = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
        const auto d =
            mesh.to_vertex_handle(mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h)));
        const Vec3d n0 = area_normal({at(a), at(b), at(c)});
        const Vec3d n1 = area_normal({at(b), at(a), at(d)});
        const Vec3d middle_point = 0.5 * (at(a) + at(b));
        const double length = (at(b) - at(a)).norm();
        const Vec3d normal = (n0.normalized() + n1.normalized()).normalized();
        if (!normal.allFinite())
            continue;
        const std::optional<Vec3d> p = project_vertex(field, middle_point, normal, length);
        if (!p)
            continue;
        const double bound =
            std::min(chord_split_min_angle * degrees,
                     std::min(min_angle(at(a), at(b), at(c)), min_angle(at(b), at(a), at(d))));
        const std::array<std::array<Vec3d, 3>, 4> parts{
            {{at(a), *p, at(c)}, {*p, at(b), at(c)}, {at(b), *p, at(d)}, {*p, at(a), at(d)}}};
        bool keeps = true;
        for (std::size_t k = 0; k < parts.size() && keeps; ++k)
        {
            const std::array<Vec3d, 3>& t = parts[k];
            keeps =
                min_angle(t[0], t[1], t[2]) >= bound && area_normal(t).dot(k < 2 ? n0 : n1) > 0.0;
        }
        if (!keeps)
            continue;
        mesh.split(e, to_om(*p));
        state.position.push_back(*p);
        state.on_surface.push_back(1);
        state.no_crossing.push_back(0);
        filled.push_back(0);
        start.push_back(middle_point);
        ++splits;
    }
    if (splits > 0)
        mesh.update_face_normals();
    return splits;
}

} // namespace

BaseMeshResult build_base_mesh(const TriMesh& intermediate, const Field& field,
                               const BaseMeshOptions& options)
{
    const auto start = std::chrono::steady_clock::now();
    check_options(options);
    BaseMeshResult result;
    BaseMeshStats& stats = result.stats;
    stats.input_faces = intermediate.face_count();
    stats.topology_before = check_intermediate_mesh(intermediate);
    const MeshTopology& before = stats.topology_before;
    stats.target_faces =
        options.target_faces
            ? *options.target_faces
            : default_base_faces(stats.input_faces, before.components, default_base_share, 1.0);
    if (stats.target_faces == 0)
    {
        throw InvalidInput("base mesh: the target face count must be at least 1, got 0");
    }
    if (stats.target_faces > stats.input_faces)
    {
        throw InvalidInput("base mesh: the target of " + std::to_string(stats.target_faces) +
                           " faces is larger than the intermediate mesh's " +
                           std::to_string(stats.input_faces) + " faces");
    }

    if (options.boundary_tolerance)
    {
        stats.boundary_tolerance = *options.boundary_tolerance;
    }
    else
    {
        std::vector<double> lengths;
        lengths.reserve(3 * intermediate.face_count());
        const auto& x = intermediate.vertices.positions;
        for (const Triangle& t : intermediate.triangles)
        {
            for (std::size_t k = 0; k < 3; ++k)
            {
                lengths.push_back(static_cast<double>((x[t[k]] - x[t[(k + 1) % 3]]).norm()));
            }
        }
        stats.boundary_tolerance = 0.5 * middle_value(std::move(lengths));
    }

    // 1. Simplify by edge collapses: a large mesh first in blocks at once (decimate_in_blocks()),
    //    then the whole.
    std::optional<TriMesh> joined;
    if (options.block_decimation_faces != 0 &&
        stats.input_faces >= options.block_decimation_faces &&
        stats.target_faces <= stats.input_faces / 4)
    {
        ProgressReporter reporter(options.progress, "base mesh: decimate in blocks");
        joined = decimate_in_blocks(intermediate, stats.target_faces, stats, options, reporter);
        stats.decimated_in_blocks = joined.has_value();
        reporter.finish();
    }
    OmMesh mesh = to_openmesh(joined ? *joined : intermediate);
    const std::size_t before_pass = mesh.n_faces();
    joined.reset();
    mesh.request_face_normals();
    mesh.update_face_normals();
    {
        ProgressReporter reporter(options.progress, "base mesh: decimate");
        DecimateObserver observer(reporter,
                                  (before_pass - std::min(before_pass, stats.target_faces)) / 2);
        collapse_to(mesh, stats.target_faces, stats, options, &observer);
        if (observer.cancelled())
        {
            throw Cancelled("base mesh: cancelled");
        }
        reporter.finish();
    }
    mesh.garbage_collection();
    std::vector<char> rim(mesh.n_vertices(), 0);
    for (const auto v : mesh.vertices())
        rim[static_cast<std::size_t>(v.idx())] = mesh.is_boundary(v) ? 1 : 0;
    std::vector<char> filled;
    const std::size_t unfilled_faces = mesh.n_faces();
    fill_holes(mesh, options.fill_holes, stats, filled);
    // The patches at the mean density of the rest: their share of its area in faces.
    const auto patch_faces = static_cast<std::size_t>(
        std::ceil(stats.hole_area_share * static_cast<double>(unfilled_faces)));
    if (stats.holes_filled > 0 && mesh.n_faces() > unfilled_faces + patch_faces)
        recoarsen_filled(mesh, unfilled_faces + patch_faces, stats, options, rim, filled);

    // 2. Shape: rounds of flips and tangential relaxation, each followed by the projection of
    // every vertex onto f = 0 (or the projection alone).
    VertexState state;
    state.position.resize(mesh.n_vertices());
    state.on_surface.assign(mesh.n_vertices(), 0);
    state.no_crossing.assign(mesh.n_vertices(), 0);
    for (const auto v : mesh.vertices())
    {
        state.position[static_cast<std::size_t>(v.idx())] = to_eigen(mesh.point(v));
    }
    std::vector<Vec3d> decimated = state.position;
    const double bound = options.min_angle_degrees * degrees;
    const auto below_bound = [&mesh, bound]() {
        std::size_t count = 0;
        for (const auto f : mesh.faces())
        {
            bool on_boundary = false;
            for (const auto v : mesh.fv_range(f))
            {
                on_boundary = on_boundary || mesh.is_boundary(v);
            }
            const std::array<Vec3d, 3> p = face_points(mesh, f);
            count += !on_boundary && min_angle(p[0], p[1], p[2]) < bound ? 1 : 0;
        }
        return count;
    };
    {
        ProgressReporter reporter(options.progress, "base mesh: shape and projection");
        const bool shape = options.max_smoothing_rounds > 0;
        std::size_t previous = std::numeric_limits<std::size_t>::max();
        for (int round = 0; round < std::max(options.max_smoothing_rounds, 1); ++round)
        {
            if (shape)
            {
                const std::size_t bad = below_bound();
                if (bad == 0 && round >= 2)
                {
                    break;
                }
                if (options.min_round_gain > 0.0 && round >= 2 &&
                    static_cast<double>(bad) >=
                        (1.0 - options.min_round_gain) * static_cast<double>(previous))
                {
                    break; // no longer improving much
                }
                previous = bad;
                if (options.project)
                {
                    stats.flips +=
                        align_to_creases(mesh, field, options.max_flip_dihedral_degrees * degrees);
                }
                stats.flips += improve_by_flips(mesh, options.max_flip_dihedral_degrees * degrees);
                ++stats.smoothing_rounds;
            }
            if (options.project)
            {
                relax_and_project(mesh, field, shape, state, filled);
                for (const auto v : mesh.vertices())
                {
                    mesh.set_point(v, to_om(state.position[static_cast<std::size_t>(v.idx())]));
                }
            }
            reporter.update(round + 1, std::max(options.max_smoothing_rounds, 1));
        }
        // The longest chords split where the surface curves (BaseMeshOptions::chord_split_share).
        if (options.project && options.chord_split_share > 0.0)
            stats.chord_splits =
                split_long_chords(mesh, field, options.chord_split_share, state, filled, decimated);
        // The vertices of a patch left off the surface (beyond the field), and those of the
        // decimated mesh that are off it next to them (the coarse marching cubes put them
        // between defined and undefined corners at the hole's rim), were moved only tangentially
        // in the rounds, and a tangential move on a curved patch steps inside it: they sagged
        // 0.01-0.05 inside a ball of radius 0.5 over a hole of the noisy blobby of bench/peers.
        // They are faired (thin plate) against the rest as it ended. Unprojected vertices away
        // from the patches keep their positions (the marching cubes' of the field).
        if (options.project && stats.holes_filled > 0)
        {
            std::vector<OmMesh::VertexHandle> free;
            std::vector<char> taken(mesh.n_vertices(), 0);
            const auto off = [&](OmMesh::VertexHandle v) {
                const auto i = static_cast<std::size_t>(v.idx());
                return state.on_surface[i] == 0 && taken[i] == 0 && !mesh.is_boundary(v);
            };
            for (const auto v : mesh.vertices())
                if (filled[static_cast<std::size_t>(v.idx())] != 0 && off(v))
                {
                    taken[static_cast<std::size_t>(v.idx())] = 1;
                    free.push_back(v);
                }
            for (std::size_t q = 0; q < free.size(); ++q)
                for (const auto w : mesh.vv_range(free[q]))
                    if (off(w))
                    {
                        taken[static_cast<std::size_t>(w.idx())] = 1;
                        free.push_back(w);
                    }
            if (fair_bilaplacian(mesh, free))
            {
                for (const auto v : free)
                    state.position[static_cast<std::size_t>(v.idx())] = to_eigen(mesh.point(v));
                // Then spread along the faired surface and flipped to better angles, as the
                // rounds did the rest: faired where the rounds left them, the patches' vertices
                // bunched into thin triangles, which refinement splits into four alike at every
                // level. Measured on three simulated fandisk scans (virtual_scan.py, seeds
                // 1-3), the finest level's triangles under 20°: 1.48 / 2.35 / 1.48% without,
                // 1.37 / 2.16 / 1.28% with; Chamfer 0.209 / 1.010 / 0.726 -> 0.205 / 0.999 /
                // 0.716 (% of the diagonal).
                relax_faired(mesh, free, state.position);
                stats.flips += improve_by_flips(mesh, options.max_flip_dihedral_degrees * degrees);
            }
        }
        reporter.finish();
    }

    // 3. Back to an indexed mesh, with the report.
    TriMesh& out = result.mesh;
    out.vertices.origin = intermediate.vertices.origin;
    out.vertices.positions.reserve(mesh.n_vertices());
    for (const auto v : mesh.vertices())
    {
        const auto i = static_cast<std::size_t>(v.idx());
        out.vertices.positions.push_back((state.position[i] - out.vertices.origin).cast<float>());
        if (options.project)
        {
            stats.unprojected += state.on_surface[i] ? 0 : 1;
        }
        stats.max_vertex_move =
            std::max(stats.max_vertex_move, (state.position[i] - decimated[i]).norm());
    }
    out.triangles.reserve(mesh.n_faces());
    for (const auto f : mesh.faces())
    {
        Triangle t{};
        int i = 0;
        for (const auto v : mesh.fv_range(f))
        {
            t[static_cast<std::size_t>(i++)] = static_cast<std::uint32_t>(v.idx());
        }
        out.triangles.push_back(t);
    }
    const AngleQuality angles = angle_quality(out);
    stats.faces = out.face_count();
    stats.vertices = out.vertex_count();
    stats.min_angle_degrees = angles.min_degrees;
    stats.mean_min_angle_degrees = angles.mean_min_degrees;
    stats.share_below_20_degrees = angles.sliver_share;
    stats.share_below_20_degrees_off_boundary = angles.interior_sliver_share;
    stats.topology_after = analyze_topology(out);
    MeshTopology expected = before;
    expected.boundary_loops -= stats.holes_filled;
    expected.euler_characteristic += static_cast<long long>(stats.holes_filled);
    stats.topology_change = describe_topology_change(expected, stats.topology_after);
    stats.topology_kept = stats.topology_change.empty();
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

// ---------------------------------------------------------------------------------------------
// Interactive base mesh.

namespace {

/// "line N" or "triangle N" (1-based) for a triangle of the input.
std::string line_of(std::span<const std::size_t> lines, std::size_t face)
{
    return lines.empty() ? "triangle " + std::to_string(face + 1)
                         : "line " + std::to_string(lines[face]);
}

/// "source:N: " or "source: triangle N: ", the prefix of a message about one triangle.
std::string where(const std::string& source, std::span<const std::size_t> lines, std::size_t face)
{
    return lines.empty() ? source + ": triangle " + std::to_string(face + 1)
                         : source + ":" + std::to_string(lines[face]);
}

} // namespace

PickedBaseMesh base_mesh_from_samples(std::span<const Triangle> triangles,
                                      const PointCloud& samples, const Field& field,
                                      const std::string& source, std::span<const std::size_t> lines)
{
    if (!lines.empty() && lines.size() != triangles.size())
    {
        throw InvalidInput("base mesh: " + std::to_string(lines.size()) + " line numbers for " +
                           std::to_string(triangles.size()) + " triangles");
    }
    if (triangles.empty())
    {
        throw InvalidInput(source + ": no triangles");
    }
    const std::size_t nf = triangles.size();
    const double diagonal = samples.bounds().diagonal();

    // Per triangle: indices, repeats, zero area, duplicates.
    std::map<std::array<std::uint32_t, 3>, std::size_t> seen;
    for (std::size_t f = 0; f < nf; ++f)
    {
        const Triangle& t = triangles[f];
        for (const std::uint32_t i : t)
        {
            if (i >= samples.size())
            {
                throw InvalidInput(where(source, lines, f) + ": sample index " + std::to_string(i) +
                                   " does not exist (there are " + std::to_string(samples.size()) +
                                   " samples)");
            }
        }
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
        {
            throw InvalidInput(where(source, lines, f) + ": degenerate triangle (" +
                               std::to_string(t[0]) + ", " + std::to_string(t[1]) + ", " +
                               std::to_string(t[2]) + ") repeats a sample");
        }
        const Vec3d a = samples.world(t[0]);
        const Vec3d cross = (samples.world(t[1]) - a).cross(samples.world(t[2]) - a);
        if (!(cross.norm() > 1e-12 * diagonal * diagonal))
        {
            throw InvalidInput(where(source, lines, f) + ": triangle (" + std::to_string(t[0]) +
                               ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) +
                               ") has zero area (its samples are collinear or coincident)");
        }
        std::array<std::uint32_t, 3> key = t;
        std::sort(key.begin(), key.end());
        const auto [it, inserted] = seen.emplace(key, f);
        if (!inserted)
        {
            throw InvalidInput(where(source, lines, f) + ": triangle (" + std::to_string(t[0]) +
                               ", " + std::to_string(t[1]) + ", " + std::to_string(t[2]) +
                               ") repeats the triangle on " + line_of(lines, it->second));
        }
    }

    // Edges: at most two triangles each.
    struct EdgeUse
    {
        std::size_t face;
        bool forward; ///< the face runs lo → hi
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<EdgeUse>> edges;
    for (std::size_t f = 0; f < nf; ++f)
    {
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t a = triangles[f][static_cast<std::size_t>(k)];
            const std::uint32_t b = triangles[f][static_cast<std::size_t>((k + 1) % 3)];
            auto& uses = edges[{std::min(a, b), std::max(a, b)}];
            uses.push_back({f, a < b});
            if (uses.size() > 2)
            {
                throw InvalidInput(
                    where(source, lines, f) + ": edge (" + std::to_string(a) + ", " +
                    std::to_string(b) + ") is shared by more than two triangles (also on " +
                    line_of(lines, uses[0].face) + " and " + line_of(lines, uses[1].face) + ")");
            }
        }
    }

    // Vertices: the triangles around a sample must form a single fan (linear in the triangles
    // whatever the valences, see vertex_fans).
    const VertexFans fans = vertex_fans(triangles, samples.size());
    for (std::size_t v = 0; v < samples.size(); ++v)
    {
        if (fans.fan_count[v] < 2)
        {
            continue;
        }
        const auto faces = fans.faces_of(v);
        const auto fan = fans.fans_of(v);
        const std::size_t i = static_cast<std::size_t>(
            std::find_if(fan.begin(), fan.end(), [](std::uint32_t n) { return n != 0; }) -
            fan.begin());
        throw InvalidInput(where(source, lines, faces[i]) + ": sample " + std::to_string(v) +
                           " is a non-manifold vertex: its triangles form more than one fan "
                           "(those on " +
                           line_of(lines, faces[0]) + " and " + line_of(lines, faces[i]) +
                           " meet only at it)");
    }
    // Consistent orientation: breadth-first over edge-adjacent triangles.
    std::vector<char> flip(nf, 0);
    std::vector<char> visited(nf, 0);
    std::vector<std::size_t> component(nf, 0);
    std::vector<std::vector<std::size_t>> neighbours(nf);
    for (const auto& [edge, uses] : edges)
    {
        if (uses.size() == 2)
        {
            neighbours[uses[0].face].push_back(uses[1].face);
            neighbours[uses[1].face].push_back(uses[0].face);
        }
    }
    const auto runs_forward = [&](std::size_t f, std::uint32_t a, std::uint32_t b) {
        const Triangle& t = triangles[f];
        for (int k = 0; k < 3; ++k)
        {
            if (t[static_cast<std::size_t>(k)] == a &&
                t[static_cast<std::size_t>((k + 1) % 3)] == b)
            {
                return flip[f] == 0;
            }
        }
        return flip[f] != 0; // the face runs b → a
    };
    std::size_t components = 0;
    std::vector<std::size_t> queue;
    for (std::size_t seed = 0; seed < nf; ++seed)
    {
        if (visited[seed])
        {
            continue;
        }
        visited[seed] = 1;
        component[seed] = components;
        queue.assign(1, seed);
        for (std::size_t head = 0; head < queue.size(); ++head)
        {
            const std::size_t f = queue[head];
            for (const std::size_t g : neighbours[f])
            {
                // The shared edge (a, b), as f runs it now.
                std::uint32_t a = 0;
                std::uint32_t b = 0;
                for (int k = 0; k < 3; ++k)
                {
                    const std::uint32_t p = triangles[f][static_cast<std::size_t>(k)];
                    const std::uint32_t q = triangles[f][static_cast<std::size_t>((k + 1) % 3)];
                    const auto& tg = triangles[g];
                    if (std::find(tg.begin(), tg.end(), p) != tg.end() &&
                        std::find(tg.begin(), tg.end(), q) != tg.end())
                    {
                        a = flip[f] ? q : p;
                        b = flip[f] ? p : q;
                    }
                }
                if (!visited[g])
                {
                    visited[g] = 1;
                    component[g] = components;
                    // g must run b → a.
                    if (runs_forward(g, a, b))
                    {
                        flip[g] = 1;
                    }
                    queue.push_back(g);
                }
                else if (runs_forward(g, a, b))
                {
                    throw InvalidInput(where(source, lines, g) +
                                       ": the triangles cannot be oriented consistently (the "
                                       "surface they form is not orientable)");
                }
            }
        }
        ++components;
    }

    // Outwards: per component, the area-weighted normals against ∇f at the vertices.
    std::vector<double> vote(components, 0.0);
    std::map<std::uint32_t, Vec3d> outward;
    for (std::uint32_t v = 0; v < samples.size(); ++v)
    {
        if (fans.faces_of(v).empty())
        {
            continue;
        }
        const Vec3d p = samples.world(v);
        const FieldSample s = field.evaluate(p);
        Vec3d g = Vec3d::Zero();
        if (s.defined && s.gradient.allFinite())
        {
            g = s.gradient;
        }
        else if (samples.has_normals())
        {
            g = samples.normals[v].cast<double>();
        }
        outward[v] = g.squaredNorm() > 0.0 ? Vec3d(g.normalized()) : Vec3d::Zero();
    }
    for (std::size_t f = 0; f < nf; ++f)
    {
        const Triangle& t = triangles[f];
        Vec3d n = (samples.world(t[1]) - samples.world(t[0]))
                      .cross(samples.world(t[2]) - samples.world(t[0]));
        if (flip[f])
        {
            n = -n;
        }
        for (const std::uint32_t v : t)
        {
            vote[component[f]] += n.dot(outward[v]);
        }
    }

    PickedBaseMesh out;
    out.mesh.vertices.origin = samples.origin;
    std::map<std::uint32_t, std::uint32_t> vertex_of;
    for (std::size_t f = 0; f < nf; ++f)
    {
        Triangle t = triangles[f];
        const bool reverse = (flip[f] != 0) != (vote[component[f]] < 0.0);
        if (reverse)
        {
            std::swap(t[1], t[2]);
            ++out.reoriented_faces;
        }
        for (std::uint32_t& v : t)
        {
            const auto [it, inserted] =
                vertex_of.emplace(v, static_cast<std::uint32_t>(out.samples.size()));
            if (inserted)
            {
                out.samples.emplace_back(v);
                out.mesh.vertices.positions.push_back(samples.positions[v]);
            }
            v = it->second;
        }
        out.mesh.triangles.push_back(t);
    }
    out.topology = analyze_topology(out.mesh);
    PF_ASSERT(out.topology.is_oriented_manifold());
    return out;
}

namespace {

std::string_view trim(std::string_view s)
{
    const auto begin = s.find_first_not_of(" \t\r\f\v");
    if (begin == std::string_view::npos)
    {
        return {};
    }
    const auto end = s.find_last_not_of(" \t\r\f\v");
    return s.substr(begin, end - begin + 1);
}

/// Triangles of an index-triple file, with the line of each.
std::pair<std::vector<Triangle>, std::vector<std::size_t>> read_index_triples(
    const std::filesystem::path& path, std::size_t sample_count)
{
    std::ifstream in(path);
    if (!in)
    {
        throw IoError(path, "cannot open the base-mesh file");
    }
    std::vector<Triangle> triangles;
    std::vector<std::size_t> lines;
    std::string line;
    std::size_t number = 0;
    const std::string name = path.string();
    while (std::getline(in, line))
    {
        ++number;
        std::string_view text = line;
        text = trim(text.substr(0, text.find('#')));
        if (text.empty())
        {
            continue;
        }
        Triangle t{};
        std::size_t count = 0;
        bool ok = true;
        while (!text.empty())
        {
            const auto space = text.find_first_of(" \t,");
            const std::string_view token = text.substr(0, space);
            text =
                space == std::string_view::npos ? std::string_view{} : trim(text.substr(space + 1));
            std::uint64_t value = 0;
            const auto [end, error] =
                std::from_chars(token.data(), token.data() + token.size(), value);
            if (error != std::errc{} || end != token.data() + token.size() || count == 3)
            {
                ok = false;
                break;
            }
            if (value >= sample_count)
            {
                throw InvalidInput(name + ":" + std::to_string(number) + ": sample index " +
                                   std::string(token) + " does not exist (there are " +
                                   std::to_string(sample_count) + " samples)");
            }
            t[count++] = static_cast<std::uint32_t>(value);
        }
        if (!ok || count != 3)
        {
            throw InvalidInput(name + ":" + std::to_string(number) +
                               ": expected three sample indices \"i j k\", got \"" +
                               std::string(trim(line)) + "\"");
        }
        triangles.push_back(t);
        lines.push_back(number);
    }
    if (in.bad())
    {
        throw IoError(path, "read error");
    }
    return {std::move(triangles), std::move(lines)};
}

} // namespace

PickedBaseMesh read_picked_base_mesh(const std::filesystem::path& path, const PointCloud& samples,
                                     const Field& field)
{
    if (samples.empty())
    {
        throw InvalidInput("base mesh: no samples to pick from");
    }
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
    {
        throw IoError(path, "the base-mesh file does not exist or is not a regular file");
    }
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const std::string name = path.string();
    if (extension != ".obj")
    {
        auto [triangles, lines] = read_index_triples(path, samples.size());
        return base_mesh_from_samples(triangles, samples, field, name, lines);
    }

    // OBJ: every used vertex snaps to its nearest sample.
    ReadResult obj = read_geometry(path, {});
    if (obj.triangles.empty())
    {
        throw InvalidInput(name + ": the OBJ file has no faces");
    }
    PickedVertices picked{.triangles = std::move(obj.triangles), .source = name};
    picked.vertices.resize(obj.points.size());
    for (std::size_t v = 0; v < picked.vertices.size(); ++v)
        picked.vertices[v] = obj.points.world(v);
    return snap_picked_base_mesh(picked, samples, field);
}

PickedVertices picked_vertices_from_samples(std::span<const Triangle> triangles,
                                            const PointCloudView& samples,
                                            const std::string& source)
{
    PickedVertices out{.source = source};
    std::map<std::uint32_t, std::uint32_t> vertex_of_sample;
    out.triangles.reserve(triangles.size());
    for (std::size_t f = 0; f < triangles.size(); ++f)
    {
        Triangle t{};
        for (std::size_t k = 0; k < 3; ++k)
        {
            const std::uint32_t s = triangles[f][k];
            if (s >= samples.size())
                throw InvalidInput(source + ": triangle " + std::to_string(f + 1) +
                                   " names sample " + std::to_string(s) + " of " +
                                   std::to_string(samples.size()));
            const auto [it, inserted] =
                vertex_of_sample.emplace(s, static_cast<std::uint32_t>(out.vertices.size()));
            if (inserted)
                out.vertices.push_back(samples.origin + samples.positions[s].cast<double>());
            t[k] = it->second;
        }
        out.triangles.push_back(t);
    }
    return out;
}

PickedBaseMesh snap_picked_base_mesh(const PickedVertices& picked, const PointCloud& samples,
                                     const Field& field)
{
    const std::string& name = picked.source;
    if (samples.empty())
    {
        throw InvalidInput(name + ": no samples to pick from");
    }
    if (picked.triangles.empty())
    {
        throw InvalidInput(name + ": no triangles");
    }
    const KdTree tree(samples.positions);
    std::vector<std::uint32_t> sample_of(picked.vertices.size(), PointId::invalid_value);
    std::map<std::uint32_t, std::size_t> vertex_of_sample;
    double max_snap = 0.0;
    std::vector<Triangle> triangles;
    triangles.reserve(picked.triangles.size());
    for (std::size_t f = 0; f < picked.triangles.size(); ++f)
    {
        const Triangle& t = picked.triangles[f];
        Triangle s{};
        for (std::size_t k = 0; k < 3; ++k)
        {
            const std::uint32_t v = t[k];
            if (v >= picked.vertices.size())
            {
                throw InvalidInput(name + ": triangle " + std::to_string(f + 1) + " names vertex " +
                                   std::to_string(v + 1) + " of " +
                                   std::to_string(picked.vertices.size()));
            }
            if (sample_of[v] == PointId::invalid_value)
            {
                const Vec3d& world = picked.vertices[v];
                if (!world.allFinite())
                {
                    throw InvalidInput(name + ": vertex " + std::to_string(v + 1) +
                                       " is not finite");
                }
                float squared = 0.0F;
                const PointId nearest =
                    tree.nearest((world - samples.origin).cast<float>(), &squared);
                const auto [it, inserted] = vertex_of_sample.emplace(nearest.value, v);
                if (!inserted)
                {
                    throw InvalidInput(name + ": vertices " + std::to_string(it->second + 1) +
                                       " and " + std::to_string(v + 1) +
                                       " snap to the same sample " + std::to_string(nearest.value));
                }
                sample_of[v] = nearest.value;
                max_snap = std::max(max_snap, (samples.world(nearest.value) - world).norm());
            }
            s[k] = sample_of[v];
        }
        triangles.push_back(s);
    }
    PickedBaseMesh out = base_mesh_from_samples(triangles, samples, field, name);
    out.max_snap_distance = max_snap;
    return out;
}

HoleFillStats fill_mesh_holes(TriMesh& mesh, double max_share)
{
    if (!(max_share >= 0.0 && max_share < 1.0))
        throw InvalidInput(
            "fill holes: the largest hole's share of its component's area must be "
            "in [0, 1), got " +
            std::to_string(max_share));
    HoleFillStats result;
    if (max_share == 0.0 || mesh.face_count() == 0)
        return result;
    const MeshTopology topology = analyze_topology(mesh);
    if (topology.boundary_loops == 0)
        return result;
    if (!topology.is_oriented_manifold())
    {
        result.skipped_not_manifold = true;
        return result;
    }
    // Every vertex and face in place (isolated vertices too), so the mesh's indices stay and
    // the patches' vertices and faces come after them.
    OmMesh om;
    const std::size_t vertex_count = mesh.vertex_count();
    if (!add_to_openmesh(mesh, om))
    {
        result.skipped_not_manifold = true; // a complex vertex analyze_topology() let pass
        return result;
    }
    BaseMeshStats stats;
    std::vector<char> filled;
    fill_holes(om, max_share, stats, filled);
    result.holes_filled = stats.holes_filled;
    result.hole_vertices = stats.hole_vertices;
    result.hole_area_share = stats.hole_area_share;
    if (stats.holes_filled == 0)
        return result;

    PointCloud& vertices = mesh.vertices;
    const std::size_t total = om.n_vertices();
    vertices.positions.resize(total);
    for (std::size_t v = vertex_count; v < total; ++v)
        vertices.positions[v] =
            (to_eigen(om.point(OmMesh::VertexHandle(static_cast<int>(v)))) - vertices.origin)
                .cast<float>();
    const std::size_t face_count = mesh.face_count();
    for (std::size_t f = face_count; f < om.n_faces(); ++f)
    {
        Triangle t{};
        std::size_t corner = 0;
        for (const auto v : om.fv_range(OmMesh::FaceHandle(static_cast<int>(f))))
            t[corner++] = static_cast<std::uint32_t>(v.idx());
        mesh.triangles.push_back(t);
    }
    // A patch vertex's normal: the area-weighted normal of its faces; its colour and radius the
    // mean of its neighbours' that have one (the rim's, inwards ring by ring).
    if (!vertices.normals.empty())
    {
        vertices.normals.resize(total);
        for (std::size_t v = vertex_count; v < total; ++v)
        {
            Vec3d sum = Vec3d::Zero();
            for (const auto f : om.vf_range(OmMesh::VertexHandle(static_cast<int>(v))))
                sum += area_normal(face_points(om, f));
            vertices.normals[v] =
                sum.norm() > 0.0 ? Vec3f(sum.normalized().cast<float>()) : Vec3f::Zero();
        }
    }
    //    Rings are added outside in, so a vertex's outer neighbours have theirs by then.
    const auto spread = [&](std::size_t channels, const auto& get, const auto& set) {
        for (std::size_t v = vertex_count; v < total; ++v)
        {
            std::array<double, 3> sum{};
            int count = 0;
            for (const auto w : om.vv_range(OmMesh::VertexHandle(static_cast<int>(v))))
                if (const auto i = static_cast<std::size_t>(w.idx()); i < v)
                {
                    for (std::size_t c = 0; c < channels; ++c)
                        sum[c] += get(i, c);
                    ++count;
                }
            if (count > 0)
                for (std::size_t c = 0; c < channels; ++c)
                    set(v, c, sum[c] / count);
        }
    };
    if (!vertices.colors.empty())
    {
        vertices.colors.resize(total);
        const auto channel = [&](std::size_t i, std::size_t c) -> std::uint8_t& {
            Color& colour = vertices.colors[i];
            return c == 0 ? colour.r : c == 1 ? colour.g : colour.b;
        };
        spread(
            3, [&](std::size_t i, std::size_t c) { return static_cast<double>(channel(i, c)); },
            [&](std::size_t i, std::size_t c, double value) {
                channel(i, c) = static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
            });
    }
    if (!vertices.radii.empty())
    {
        vertices.radii.resize(total);
        spread(
            1, [&](std::size_t i, std::size_t) { return static_cast<double>(vertices.radii[i]); },
            [&](std::size_t i, std::size_t, double value) {
                vertices.radii[i] = static_cast<float>(value);
            });
    }
    return result;
}

} // namespace pointform
