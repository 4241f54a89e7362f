// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/surfels.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/hermite/crease_fit.h"
#include "pointform/hermite/normals.h"
#include "pointform/hermite/scatter.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include "orientation_detail.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <string_view>

namespace pointform {
namespace {

/// Second-largest over largest eigenvalue of the whole cloud's covariance below which all points
/// are taken to lie on one line. Relative, so unit-free; float storage noise is about 1e-14.
constexpr double global_collinear_ratio = 1e-12;
/// The largest extent of a cloud that can carry surfels: its squared distances (three squares
/// summed in float) stay below float's largest value, 3.4e38.
constexpr double max_extent = 1e18;

/// Samples a block when the cloud is put into Morton order and back.
constexpr std::size_t gather_block = 1U << 16U;

class StageTimer
{
public:
    explicit StageTimer(std::vector<std::pair<std::string, double>>& log) : log_(log) {}

    /// Logs the time since the last lap (plus `earlier`, taken from this stage's other parts).
    void lap(const std::string& stage, double earlier = 0.0)
    {
        log_.emplace_back(stage, take() + earlier);
    }
    /// The time since the last lap, not logged.
    double take()
    {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - last_).count();
        last_ = now;
        return seconds;
    }

private:
    std::vector<std::pair<std::string, double>>& log_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// Whether the bulk of a cloud spans a plane although its whole covariance says that the points
/// lie on one line or at one place: one point far enough away (a stray return at 1e20) makes
/// every other spread vanish beside its own. Up to 65,536 points taken at an even stride,
/// without the 2% of them farthest from their coordinate-wise median.
bool bulk_spans_a_plane(std::span<const Vec3f> positions)
{
    const std::size_t stride = std::max<std::size_t>(1, positions.size() / 65536);
    std::vector<Vec3d> sample;
    for (std::size_t i = 0; i < positions.size(); i += stride)
        sample.push_back(positions[i].cast<double>());
    const auto middle = static_cast<std::ptrdiff_t>(sample.size() / 2);
    Vec3d centre;
    std::vector<double> values(sample.size());
    for (Eigen::Index axis = 0; axis < 3; ++axis)
    {
        for (std::size_t j = 0; j < sample.size(); ++j)
            values[j] = sample[j][axis];
        std::nth_element(values.begin(), values.begin() + middle, values.end());
        centre[axis] = values[static_cast<std::size_t>(middle)];
    }
    for (std::size_t j = 0; j < sample.size(); ++j)
        values[j] = (sample[j] - centre).squaredNorm();
    std::vector<double> sorted = values;
    const auto cut = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() * 98 / 100);
    std::nth_element(sorted.begin(), cut, sorted.end());
    const double limit = *cut;
    Vec3d sum = Vec3d::Zero();
    Mat3d products = Mat3d::Zero();
    double count = 0.0;
    for (std::size_t j = 0; j < sample.size(); ++j)
        if (values[j] <= limit)
        {
            const Vec3d d = sample[j] - centre;
            sum += d;
            products.noalias() += d * d.transpose();
            count += 1.0;
        }
    const Vec3d mean = sum / count;
    const Mat3d covariance = products / count - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3d> solver(covariance, Eigen::EigenvaluesOnly);
    const Vec3d& lambda = solver.eigenvalues();
    return lambda[2] > 0.0 && lambda[1] > global_collinear_ratio * lambda[2];
}

} // namespace

void check_surfel_input(const PointCloudView& cloud, std::size_t k)
{
    validate(cloud);
    if (k < 3)
        throw InvalidInput("k = " + std::to_string(k) +
                           " is too small: a tangent plane needs at least 3 neighbours");
    const std::size_t n = cloud.size();
    if (n <= k)
        throw InvalidInput("only " + std::to_string(n) + " points, fewer than k + 1 = " +
                           std::to_string(k + 1) + " (a point and its k neighbours)");

    // One pass, in parallel blocks whose sums are added in block order (the same bits at any
    // thread count): the first non-finite point, and the moments about the first point (close
    // to the cloud, so the covariance loses little to cancellation).
    const std::size_t blocks = (n + gather_block - 1) / gather_block;
    struct Moments
    {
        std::size_t first_bad = ~std::size_t{0};
        Vec3d sum = Vec3d::Zero();
        Mat3d products = Mat3d::Zero();
        Vec3d low = Vec3d::Constant(std::numeric_limits<double>::infinity());
        Vec3d high = Vec3d::Constant(-std::numeric_limits<double>::infinity());
    };
    std::vector<Moments> parts(blocks);
    const Vec3d pivot = cloud.positions[0].cast<double>();
    parallel_blocks(blocks, 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t b = first; b < last; ++b)
        {
            Moments& part = parts[b];
            for (std::size_t i = b * gather_block; i < std::min(n, (b + 1) * gather_block); ++i)
            {
                if (!cloud.positions[i].allFinite())
                {
                    part.first_bad = std::min(part.first_bad, i);
                    continue;
                }
                const Vec3d d = cloud.positions[i].cast<double>() - pivot;
                part.sum += d;
                part.products.noalias() += d * d.transpose();
                part.low = part.low.cwiseMin(d);
                part.high = part.high.cwiseMax(d);
            }
        }
    });
    Vec3d sum = Vec3d::Zero();
    Mat3d products = Mat3d::Zero();
    Vec3d low = Vec3d::Zero(); // the pivot is a point
    Vec3d high = Vec3d::Zero();
    for (const Moments& part : parts)
    {
        if (part.first_bad != ~std::size_t{0})
            throw InvalidInput("point " + std::to_string(part.first_bad) +
                               " has a NaN or infinite coordinate");
        sum += part.sum;
        products += part.products;
        low = low.cwiseMin(part.low);
        high = high.cwiseMax(part.high);
    }
    // Squared distances are summed in float by the kd-tree: beyond about 1.8e19 they overflow.
    const double span = (high - low).maxCoeff();
    if (span > max_extent)
        throw InvalidInput("the points span " + std::to_string(span) + " units, more than " +
                           std::to_string(max_extent) +
                           ", where distances overflow single precision: remove the far "
                           "outliers");
    const Vec3d mean = sum / static_cast<double>(n);
    const Mat3d covariance = products - static_cast<double>(n) * mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3d> solver(covariance, Eigen::EigenvaluesOnly);
    const Vec3d& lambda = solver.eigenvalues();
    const bool coincide = !(lambda[2] > 0.0);
    const bool line = !coincide && lambda[1] <= global_collinear_ratio * lambda[2];
    if (!coincide && !line)
        return;
    // Far outliers can make a surface look like a line: only the bulk decides.
    if (bulk_spans_a_plane(cloud.positions))
        return;
    if (coincide)
        throw InvalidInput("all " + std::to_string(cloud.size()) +
                           " points coincide: no surface to estimate");
    throw InvalidInput("all points lie on one line: no surface normal is defined");
}

namespace {

/// The position array of the cloud that compute_surfels() was given to own, lent to the work
/// while `sorted` holds the same points in Morton order (sorted[j] is the owner's point order[j]):
/// the guide's normals are written into it, so that the points are not held twice during the
/// orientation's peak. Given back in the owner's order, the points exactly as they were, when the
/// work is done or when anything throws (no allocation: the owner's cloud is unchanged).
class LentPositions
{
public:
    LentPositions(PointCloud* owner, const std::vector<Vec3f>& sorted,
                  const std::vector<std::uint32_t>& order)
        : owner_(owner), sorted_(sorted), order_(order)
    {
        if (owner_ != nullptr)
            buffer_ = std::move(owner_->positions);
    }
    LentPositions(const LentPositions&) = delete;
    LentPositions& operator=(const LentPositions&) = delete;
    LentPositions(LentPositions&&) = delete;
    LentPositions& operator=(LentPositions&&) = delete;
    ~LentPositions()
    {
        if (owner_ != nullptr)
            put_back(sorted_.size());
    }

    /// A slot for every sample, or none when nothing was lent.
    [[nodiscard]] std::span<Vec3f> scratch() { return buffer_; }

    /// Puts the points back in the owner's order (in parallel) and returns the array to it.
    void give_back()
    {
        if (owner_ == nullptr)
            return;
        parallel_blocks(sorted_.size(), gather_block,
                        [&](std::size_t begin, std::size_t end) { scatter(begin, end); });
        put_back(0);
    }

private:
    // Points [begin, end) of `sorted` go back to their places; the rest were put back already.
    void scatter(std::size_t begin, std::size_t end) noexcept
    {
        for (std::size_t j = begin; j < end; ++j)
            buffer_[order_[j]] = sorted_[j];
    }
    void put_back(std::size_t unscattered) noexcept
    {
        scatter(0, unscattered);
        owner_->positions = std::move(buffer_);
        owner_ = nullptr;
    }

    PointCloud* owner_;
    const std::vector<Vec3f>& sorted_;
    const std::vector<std::uint32_t>& order_;
    std::vector<Vec3f> buffer_;
};

/// Rows of `table` (over `positions`, each the point itself and its nearest, nearest first) that
/// hold one of `gone` (ascending) take the next nearest instead, from `tree`; the rows of `gone`
/// stay as they are, and so does a row that too few other points could fill.
void take_out_of_rows(const KdTree& tree, std::span<const Vec3f> positions,
                      std::span<const std::uint32_t> gone, KnnTable& table)
{
    if (gone.empty())
        return;
    std::vector<std::uint8_t> is_gone(positions.size(), 0);
    for (const std::uint32_t g : gone)
        is_gone[g] = 1;
    const std::size_t width = table.k;
    const bool all_distances = table.has_all_distances();
    parallel_blocks(table.rows(), 4096, [&](std::size_t begin, std::size_t end) {
        std::vector<std::uint32_t> index;
        std::vector<float> d2;
        std::vector<std::uint32_t> row_index;
        std::vector<float> row_d2;
        for (std::size_t i = begin; i < end; ++i)
        {
            const std::span<const std::uint32_t> row = table.neighbors(i);
            if (is_gone[i] != 0 || std::none_of(row.begin(), row.end(),
                                                [&](std::uint32_t j) { return is_gone[j] != 0; }))
                continue;
            for (std::size_t want = width + 8;; want *= 2)
            {
                index.resize(want);
                d2.resize(want);
                const std::size_t got = tree.knn(positions[i], want, index, d2);
                row_index.clear();
                row_d2.clear();
                for (std::size_t j = 0; j < got && row_index.size() < width; ++j)
                    if (is_gone[index[j]] == 0)
                    {
                        row_index.push_back(index[j]);
                        row_d2.push_back(d2[j]);
                    }
                if (row_index.size() == width || got < want)
                    break;
            }
            if (row_index.size() < width)
                continue;
            std::copy(row_index.begin(), row_index.end(),
                      table.indices.begin() + static_cast<std::ptrdiff_t>(i * width));
            if (all_distances)
                std::copy(row_d2.begin(), row_d2.end(),
                          table.squared_distances.begin() + static_cast<std::ptrdiff_t>(i * width));
            else
                table.squared_distances[i] = row_d2.back();
        }
    });
}

/// The three numbers of "X,Y,Z" (spaces around each allowed, a leading '+' too), finite.
Vec3d parse_three(std::string_view text, std::string_view whole)
{
    Vec3d v;
    std::size_t start = 0;
    for (int axis = 0; axis < 3; ++axis)
    {
        const std::size_t comma = axis < 2 ? text.find(',', start) : text.size();
        std::string_view token = comma == std::string_view::npos
                                     ? std::string_view{}
                                     : text.substr(start, comma - start);
        while (!token.empty() && (token.front() == ' ' || token.front() == '\t'))
            token.remove_prefix(1);
        while (!token.empty() && (token.back() == ' ' || token.back() == '\t'))
            token.remove_suffix(1);
        if (token.size() > 1 && token.front() == '+' && token[1] != '-')
            token.remove_prefix(1);
        double value = 0.0;
        const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
        if (token.empty() || error != std::errc{} || end != token.data() + token.size() ||
            !std::isfinite(value))
            throw InvalidInput("orientation '" + std::string(whole) +
                               "': expected three finite numbers X,Y,Z");
        v[axis] = value;
        start = comma + 1;
    }
    return v;
}

/// compute_surfels() of `cloud`; when `owner` is given (the cloud that `cloud` views, no longer
/// needed by the caller), its positions and colours are moved into the result, not copied.
SurfelResult surfels_of(const PointCloudView& cloud, const SurfelOptions& requested,
                        PointCloud* owner)
{
    SurfelResult result;
    // OrientMode::Auto: towards the cloud's sensor where it was seen from one, else MST.
    SurfelOptions options = requested;
    if (options.orient == OrientMode::Towards && !options.orient_target.allFinite())
        throw InvalidInput("the viewpoint to orient normals towards is not finite");
    if (options.orient == OrientMode::Along &&
        (!options.orient_target.allFinite() || options.orient_target.squaredNorm() == 0.0))
        throw InvalidInput("the direction to orient normals along must be finite and not zero");
    if (options.orient == OrientMode::Auto)
    {
        if (cloud.sensor && !cloud.sensor->allFinite())
            throw InvalidInput("the cloud's sensor position is not finite");
        result.towards_sensor = cloud.sensor.has_value();
        options.orient = cloud.sensor ? OrientMode::Towards : OrientMode::Mst;
        if (cloud.sensor)
            options.orient_target = *cloud.sensor;
    }
    StageTimer timer(result.stage_seconds);
    check_surfel_input(cloud, options.k);
    if (!(options.radius_scale > 0.0) || !std::isfinite(options.radius_scale))
        throw InvalidInput("radius scale must be positive and finite");
    timer.lap("check");
    const std::size_t n = cloud.size();

    // Work on the points in Morton order, so that neighbours are close in memory; map back at
    // the end. The order depends only on the positions, so results do not depend on threads.
    // Samples at one place are one surfel: the rest is worked out on the distinct places (in
    // the same order), and every copy takes its original's normal and radius.
    std::vector<CoincidentCopy> copies;
    const std::vector<std::uint32_t> order = spatial_order(cloud.positions, copies);
    std::vector<Vec3f> sorted(n);
    parallel_blocks(n, gather_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
            sorted[j] = cloud.positions[order[j]];
    });
    std::vector<Vec3f> distinct;
    std::vector<std::uint32_t> place; // sorted index -> index in `distinct`; empty: no copies
    if (!copies.empty())
    {
        std::vector<std::uint32_t> original(n);
        for (std::size_t i = 0; i < n; ++i)
            original[i] = static_cast<std::uint32_t>(i);
        for (const CoincidentCopy& c : copies)
            original[c.copy] = c.original;
        // The places in sorted order: an original's place, taken by its copies.
        std::vector<std::uint32_t> place_of(n);
        distinct.reserve(n - copies.size());
        for (std::size_t j = 0; j < n; ++j)
            if (original[order[j]] == order[j])
            {
                place_of[order[j]] = static_cast<std::uint32_t>(distinct.size());
                distinct.push_back(sorted[j]);
            }
        place.resize(n);
        for (std::size_t j = 0; j < n; ++j)
            place[j] = place_of[original[order[j]]];
        if (distinct.size() <= options.k)
            throw InvalidInput("only " + std::to_string(distinct.size()) +
                               " distinct points (the others repeat their coordinates), fewer "
                               "than k + 1 = " +
                               std::to_string(options.k + 1));
        result.copies.reserve(copies.size());
        for (const CoincidentCopy& c : copies)
            result.copies.push_back(c.copy);
    }
    timer.lap("spatial sort");
    LentPositions lent(owner, sorted, order);
    const std::span<const Vec3f> positions =
        place.empty() ? std::span<const Vec3f>(sorted) : std::span<const Vec3f>(distinct);

    // Only the k-th distance is needed (radii, the orientation's flux); the tree goes once the
    // table is made.
    KnnTable table;
    std::vector<std::uint32_t> off_surface; // indices into `positions`
    {
        const KdTree tree(positions);
        timer.lap("kd-tree");
        table = knn_batch(tree, positions, options.k + 1,
                          {.farthest_distance_only = true, .progress = options.progress});
        timer.lap("knn");
        if (options.off_surface)
        {
            off_surface = off_surface_samples(positions, table);
            take_out_of_rows(tree, positions, off_surface, table);
            timer.lap("off surface");
        }
    }
    // The orientation's guide (noisy clouds) before the fine normals, so that the two never take
    // memory at once; its normals go into the lent array.
    const bool by_graph = options.orient == OrientMode::Mst || options.orient == OrientMode::Flip;
    const OrientationOptions graph_options{
        .k = options.graph_k == 0 ? std::min<std::size_t>(options.k, 10) : options.graph_k,
        .rule = options.rule,
        .progress = options.progress};
    detail::Guide guide;
    if (by_graph)
        guide = detail::grow_guide(positions, table, graph_options, lent.scratch());
    const double guide_seconds = timer.take();
    // A clean cloud's normals are refitted to the nearest neighbours where the neighbourhood
    // reaches the far side of a thin part (NeighbourWeights::Local); a noisy cloud's take every
    // neighbour alike, averaging the noise.
    const NeighbourWeights weights =
        detail::clean_table(positions, table) ? NeighbourWeights::Local : NeighbourWeights::Uniform;
    Normals normals = estimate_normals(positions, table, options.progress, weights);
    result.degenerate = normals.degenerate.size();
    timer.lap("normals");

    OrientedNormals oriented;
    switch (options.orient)
    {
        case OrientMode::Auto: // resolved above: not reached
        case OrientMode::Mst:
        case OrientMode::Flip:
        {
            // estimate_normals() checked every row of the table.
            oriented = detail::orient_with_guide(positions, normals.normals, table, graph_options,
                                                 std::move(guide));
            if (options.orient == OrientMode::Flip)
            {
                OrientedNormals flipped = flip_normals(oriented.normals);
                oriented.normals = std::move(flipped.normals);
                oriented.flipped = positions.size() - oriented.flipped;
            }
            break;
        }
        case OrientMode::None:
            oriented.normals = normals.normals;
            break;
        case OrientMode::Towards:
            oriented = orient_normals_towards(positions, normals.normals,
                                              options.orient_target - cloud.origin);
            break;
        case OrientMode::Along:
            oriented = orient_normals_along(normals.normals, options.orient_target);
            break;
    }
    timer.lap("orientation", guide_seconds);
    if (options.sharp_creases)
    {
        result.crease_refits = detail::refit_crease_normals(positions, table, oriented.normals);
        timer.lap("creases");
    }

    std::vector<float> radii = influence_radii(table, options.radius_scale);
    radii = apply_radius_regions(positions, cloud.origin, std::move(radii), options.radius_regions);
    result.isolated = isolated_samples(positions, table);
    if (!place.empty())
    {
        // Back from the places to every sample in sorted order.
        std::vector<Vec3f> spread_normals(n);
        std::vector<float> spread_radii(n);
        std::vector<std::uint8_t> isolated_place(positions.size(), 0);
        std::vector<std::uint8_t> off_surface_place(positions.size(), 0);
        std::vector<std::uint8_t> unoriented_place(positions.size(), 0);
        for (const std::uint32_t p : result.isolated)
            isolated_place[p] = 1;
        for (const std::uint32_t p : off_surface)
            off_surface_place[p] = 1;
        for (const std::uint32_t p : oriented.unoriented)
            unoriented_place[p] = 1;
        result.isolated.clear();
        off_surface.clear();
        oriented.unoriented.clear();
        for (std::size_t j = 0; j < n; ++j)
        {
            const std::uint32_t p = place[j];
            spread_normals[j] = oriented.normals[p];
            spread_radii[j] = radii[p];
            if (isolated_place[p] != 0)
                result.isolated.push_back(static_cast<std::uint32_t>(j));
            if (off_surface_place[p] != 0)
                off_surface.push_back(static_cast<std::uint32_t>(j));
            if (unoriented_place[p] != 0)
                oriented.unoriented.push_back(static_cast<std::uint32_t>(j));
        }
        oriented.normals = std::move(spread_normals);
        normals.normals.assign(n, Vec3f::Zero()); // the output's buffer below
        radii = std::move(spread_radii);
    }
    result.radius = summarize_radii(radii);
    for (auto& index : result.isolated)
        index = order[index];
    std::sort(result.isolated.begin(), result.isolated.end());
    for (auto& index : off_surface)
        index = order[index];
    std::sort(off_surface.begin(), off_surface.end());
    result.off_surface = std::move(off_surface);
    timer.lap("radius");

    // Back to the input order. The PCA normals' array (its pages already mapped) takes the
    // oriented normals.
    result.surfels.origin = cloud.origin;
    result.surfels.sensor = cloud.sensor;
    result.surfels.radii.resize(n);
    //    Nothing throws from here on, so the owner's cloud is unchanged if anything did.
    const bool moved = owner != nullptr;
    lent.give_back();
    if (moved)
    {
        result.surfels.positions = std::move(owner->positions);
        result.surfels.colors = std::move(owner->colors);
        *owner = PointCloud{};
    }
    else
    {
        result.surfels.colors.assign(cloud.colors.begin(), cloud.colors.end());
        result.surfels.positions.resize(n); // every entry written below, in parallel
    }
    result.surfels.normals = std::move(normals.normals);
    //    Sample order[j] takes the sorted sample j's normal and radius: read in order, written
    //    at random (order is a permutation, so no two blocks write one entry).
    parallel_blocks(n, gather_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
        {
            const std::uint32_t i = order[j];
            result.surfels.normals[i] = oriented.normals[j];
            result.surfels.radii[i] = radii[j];
        }
    });
    if (!moved)
        parallel_blocks(n, gather_block, [&](std::size_t begin, std::size_t end) {
            std::copy(cloud.positions.begin() + static_cast<std::ptrdiff_t>(begin),
                      cloud.positions.begin() + static_cast<std::ptrdiff_t>(end),
                      result.surfels.positions.begin() + static_cast<std::ptrdiff_t>(begin));
        });
    // The normals are the surfels'; the report keeps the rest.
    result.orientation = std::move(oriented);
    std::vector<Vec3f>().swap(result.orientation.normals);
    for (auto& index : result.orientation.unoriented)
        index = order[index];
    std::sort(result.orientation.unoriented.begin(), result.orientation.unoriented.end());
    timer.lap("output order");
    return result;
}

} // namespace

SurfelResult compute_surfels(const PointCloudView& cloud, const SurfelOptions& options)
{
    return surfels_of(cloud, options, nullptr);
}

SurfelResult compute_surfels(PointCloud&& cloud, const SurfelOptions& options)
{
    return surfels_of(cloud, options, &cloud);
}

OrientChoice parse_orient(std::string_view text)
{
    constexpr std::string_view expected =
        "': expected auto, mst, none, flip, towards:X,Y,Z or along:X,Y,Z";
    const std::size_t colon = text.find(':');
    const std::string_view mode = text.substr(0, colon);
    const std::string_view argument =
        colon == std::string_view::npos ? std::string_view{} : text.substr(colon + 1);
    const bool targeted = mode == "towards" || mode == "along";
    if (targeted == (colon == std::string_view::npos))
        throw InvalidInput("orientation '" + std::string(text) + std::string(expected));
    OrientChoice choice;
    if (mode == "auto")
        choice.mode = OrientMode::Auto;
    else if (mode == "mst")
        choice.mode = OrientMode::Mst;
    else if (mode == "none")
        choice.mode = OrientMode::None;
    else if (mode == "flip")
        choice.mode = OrientMode::Flip;
    else if (mode == "towards")
    {
        choice.mode = OrientMode::Towards;
        choice.target = parse_three(argument, text);
    }
    else if (mode == "along")
    {
        choice.mode = OrientMode::Along;
        choice.target = parse_three(argument, text);
        if (choice.target.squaredNorm() == 0.0)
            throw InvalidInput("orientation '" + std::string(text) +
                               "': the direction must not be zero");
    }
    else
        throw InvalidInput("orientation '" + std::string(text) + std::string(expected));
    return choice;
}

} // namespace pointform
