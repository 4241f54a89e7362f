// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/operators.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace pointform {
namespace {

using FieldPtr = std::shared_ptr<const Field>;

constexpr double infinity = std::numeric_limits<double>::infinity();

/// Points per block of an operator's batch evaluation: its members answer each block together.
constexpr std::size_t operator_block = 1024;

/// An operator's cost: its own and its distinct members' (a member given twice is asked once
/// per point only if it is a SharedField, but counting it once keeps costs from doubling per
/// level of a shared chain).
double summed_cost(std::span<const FieldPtr> members)
{
    double sum = 1.0;
    for (std::size_t i = 0; i < members.size(); ++i)
    {
        bool seen = false;
        for (std::size_t j = 0; j < i && !seen; ++j)
        {
            seen = members[j] == members[i];
        }
        if (!seen)
        {
            sum += members[i]->cost();
        }
    }
    return sum;
}

/// [lo, hi] moved by `shift` and widened by a few rounding errors, so that a member's value that
/// the operator's rounding puts within the operator's range is within the member's.
std::pair<double, double> shifted_range(double lo, double hi, double shift)
{
    const auto moved = [shift](double x, double direction) {
        if (!std::isfinite(x))
        {
            return x;
        }
        const double y = x + shift;
        return y + direction * 4.0 * std::numeric_limits<double>::epsilon() *
                       (std::abs(y) + std::abs(shift) + std::abs(x));
    };
    return {moved(lo, -1.0), moved(hi, 1.0)};
}

void require_member(const FieldPtr& member, const char* what)
{
    if (member == nullptr)
    {
        throw InvalidInput(std::string(what) + ": missing field");
    }
}

void require_members(const std::vector<FieldPtr>& members, std::size_t minimum, const char* what)
{
    if (members.size() < minimum)
    {
        throw InvalidInput(std::string(what) + " needs at least " + std::to_string(minimum) +
                           " fields, got " + std::to_string(members.size()));
    }
    for (const FieldPtr& m : members)
    {
        require_member(m, what);
    }
}

/// Whether a member's sample lets the result be defined, under the policy.
bool usable(const FieldSample& s, UndefinedPolicy policy)
{
    switch (policy)
    {
        case UndefinedPolicy::Propagate:
            return s.defined;
        case UndefinedPolicy::TrustOutside:
            return s.defined || s.value > 0.0;
        case UndefinedPolicy::Ignore:
            return true;
    }
    return s.defined;
}

Aabb union_of(const Aabb& a, const Aabb& b)
{
    if (a.is_empty())
    {
        return b;
    }
    if (b.is_empty())
    {
        return a;
    }
    return {.min = a.min.cwiseMin(b.min), .max = a.max.cwiseMax(b.max)};
}

Aabb intersection_of(const Aabb& a, const Aabb& b)
{
    return {.min = a.min.cwiseMax(b.min), .max = a.max.cwiseMin(b.max)};
}

Aabb grown(Aabb box, double margin)
{
    if (!box.is_empty() && margin > 0.0)
    {
        box.min -= Vec3d::Constant(margin);
        box.max += Vec3d::Constant(margin);
    }
    return box;
}

/// A one-member operator's batch evaluation: point i's member range is range(lo[i], hi[i]), its
/// result finish(the member's sample), as one by one.
template <class Range, class Finish>
void unary_batch(const Field& member, std::span<const Vec3d> points, std::span<const double> lo,
                 std::span<const double> hi, std::span<FieldSample> out, const Range& range,
                 const Finish& finish)
{
    check_within_sizes("unary operator evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    parallel_blocks(points.size(), operator_block, [&](std::size_t begin, std::size_t end) {
        const std::size_t n = end - begin;
        std::vector<double> member_lo(n);
        std::vector<double> member_hi(n);
        std::vector<FieldSample> samples(n);
        for (std::size_t j = 0; j < n; ++j)
        {
            std::tie(member_lo[j], member_hi[j]) = range(lo[begin + j], hi[begin + j]);
        }
        member.evaluate_within(points.subspan(begin, n), member_lo, member_hi, samples);
        for (std::size_t j = 0; j < n; ++j)
        {
            out[begin + j] = finish(samples[j]);
        }
    });
}

FieldSample offset_of(FieldSample s, double distance, UndefinedPolicy policy)
{
    s.defined = usable(s, policy);
    s.value -= distance;
    return s;
}

/// |f| − t/2 ≤ hi needs |f| ≤ hi + t/2; nothing is below −t/2, so `lo` bounds nothing.
std::pair<double, double> shell_range(double lo, double hi, double thickness)
{
    const double reach = shifted_range(lo, hi, 0.5 * thickness).second;
    return {-reach, reach};
}

FieldSample shell_of(FieldSample s, double thickness, UndefinedPolicy policy)
{
    s.defined = usable(s, policy);
    if (s.value < 0.0)
    {
        s.value = -s.value;
        s.gradient = -s.gradient;
    }
    s.value -= 0.5 * thickness;
    return s;
}

/// Newton steps p ← p − f(p)·∇f/‖∇f‖² on seeds[first..], each step at most `max_step` long,
/// so that seeds of the members land on the operator's displaced surface.
void project_seeds(const Field& field, std::vector<Vec3d>& seeds, std::size_t first, int iterations)
{
    if (first >= seeds.size())
    {
        return;
    }
    const Aabb box = field.bounds();
    const double diagonal = box.diagonal();
    const double max_step =
        std::isfinite(diagonal) && diagonal > 0.0 ? diagonal : std::numeric_limits<double>::max();
    const std::span<Vec3d> points(seeds.data() + first, seeds.size() - first);
    std::vector<FieldSample> samples(points.size());
    for (int it = 0; it < iterations; ++it)
    {
        field.evaluate(points, samples);
        for (std::size_t i = 0; i < points.size(); ++i)
        {
            const FieldSample& s = samples[i];
            const double g2 = s.gradient.squaredNorm();
            if (!(g2 > 1e-24) || !std::isfinite(s.value))
            {
                continue;
            }
            Vec3d step = -s.value / g2 * s.gradient;
            const double length = step.norm();
            if (length > max_step)
            {
                step *= max_step / length;
            }
            if (step.allFinite())
            {
                points[i] += step;
            }
        }
    }
}

/// Candidate seeds of an operator: points near its members' surfaces, each with the member's
/// |value| there (how near zero the member itself is at its seed).
struct Candidates
{
    std::vector<Vec3d> points;
    std::vector<double> slack;
    bool complete = true; ///< false if a member knows no seeds: then neither does the operator
};

/// Adds `member`'s seeds to the candidates (a member that appears twice: once).
void gather(const FieldPtr& member, Candidates& c, std::vector<const Field*>& seen)
{
    if (std::find(seen.begin(), seen.end(), member.get()) != seen.end())
    {
        return;
    }
    seen.push_back(member.get());
    const std::size_t first = c.points.size();
    member->append_seeds(c.points);
    if (c.points.size() == first)
    {
        c.complete = false;
        return;
    }
    std::vector<FieldSample> samples(c.points.size() - first);
    member->evaluate(std::span<const Vec3d>(c.points).subspan(first), samples);
    for (const FieldSample& s : samples)
    {
        c.slack.push_back(std::isfinite(s.value) ? std::abs(s.value) : 0.0);
    }
}

Candidates gather_all(std::span<const FieldPtr> members)
{
    Candidates c;
    std::vector<const Field*> seen;
    for (const FieldPtr& m : members)
    {
        gather(m, c, seen);
        if (!c.complete)
        {
            break;
        }
    }
    return c;
}

/// Rounding and Newton's leftovers: what counts as zero near p for a field over `box`.
double zero_tolerance(const Aabb& box, const Vec3d& p)
{
    const double diagonal = box.is_empty() ? 0.0 : box.diagonal();
    const double size = std::isfinite(diagonal) ? diagonal : 0.0;
    const double at = p.allFinite() ? p.cwiseAbs().maxCoeff() : 0.0;
    return 1e-6 * size + 1e-9 * (1.0 + at);
}

/// Appends the candidates where `field` is as near zero as the member was there (or within the
/// tolerance); returns how many.
std::size_t keep_near_zero(const Field& field, std::span<const Vec3d> points,
                           std::span<const double> slack, std::vector<Vec3d>& seeds)
{
    std::vector<FieldSample> samples(points.size());
    field.evaluate(points, samples);
    const Aabb box = field.bounds();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const double v = std::abs(samples[i].value);
        if (points[i].allFinite() && v <= std::max(slack[i], zero_tolerance(box, points[i])))
        {
            seeds.push_back(points[i]);
            ++kept;
        }
    }
    return kept;
}

/// Seeds where a coarse sweep of the field's bounds finds its sign change between neighbouring
/// nodes (both defined), moved onto the surface by Newton steps; none if the bounds are not
/// finite.
void sweep_seeds(const Field& field, std::vector<Vec3d>& seeds)
{
    const Aabb box = field.bounds();
    if (box.is_empty() || !box.min.allFinite() || !box.max.allFinite())
    {
        return;
    }
    constexpr int cells = 32;
    const double longest = (box.max - box.min).maxCoeff();
    const double h = longest > 0.0 ? longest / cells : 1e-3 * (1.0 + box.max.cwiseAbs().maxCoeff());
    if (!(h > 0.0) || !std::isfinite(h))
    {
        return;
    }
    // Half a cell of margin: a surface may touch the bounds (a sphere its box).
    const Vec3d origin = box.min - Vec3d::Constant(0.5 * h);
    std::array<std::size_t, 3> n{};
    for (int a = 0; a < 3; ++a)
    {
        const double span = box.max[a] - box.min[a] + h;
        n[static_cast<std::size_t>(a)] =
            static_cast<std::size_t>(std::clamp(std::ceil(span / h), 1.0, double{cells + 1})) + 1;
    }
    const auto index = [&n](std::size_t i, std::size_t j, std::size_t k) {
        return i + n[0] * (j + n[1] * k);
    };
    std::vector<Vec3d> nodes(n[0] * n[1] * n[2]);
    for (std::size_t k = 0; k < n[2]; ++k)
    {
        for (std::size_t j = 0; j < n[1]; ++j)
        {
            for (std::size_t i = 0; i < n[0]; ++i)
            {
                nodes[index(i, j, k)] =
                    origin + h * Vec3d(static_cast<double>(i), static_cast<double>(j),
                                       static_cast<double>(k));
            }
        }
    }
    std::vector<FieldSample> samples(nodes.size());
    field.evaluate(nodes, samples);
    std::vector<Vec3d> found;
    const auto edge = [&](std::size_t a, std::size_t b) {
        const FieldSample& sa = samples[a];
        const FieldSample& sb = samples[b];
        if (!sa.defined || !sb.defined || !std::isfinite(sa.value) || !std::isfinite(sb.value) ||
            (sa.value < 0.0) == (sb.value < 0.0))
        {
            return;
        }
        const double t = sa.value / (sa.value - sb.value);
        found.push_back(nodes[a] + std::clamp(t, 0.0, 1.0) * (nodes[b] - nodes[a]));
    };
    for (std::size_t k = 0; k < n[2]; ++k)
    {
        for (std::size_t j = 0; j < n[1]; ++j)
        {
            for (std::size_t i = 0; i < n[0]; ++i)
            {
                const std::size_t at = index(i, j, k);
                if (i + 1 < n[0])
                {
                    edge(at, index(i + 1, j, k));
                }
                if (j + 1 < n[1])
                {
                    edge(at, index(i, j + 1, k));
                }
                if (k + 1 < n[2])
                {
                    edge(at, index(i, j, k + 1));
                }
            }
        }
    }
    if (found.empty())
    {
        return;
    }
    std::vector<Vec3d> moved = found;
    project_seeds(field, moved, 0, 3);
    std::vector<FieldSample> before(found.size());
    std::vector<FieldSample> after(found.size());
    field.evaluate(found, before);
    field.evaluate(moved, after);
    for (std::size_t i = 0; i < found.size(); ++i)
    {
        // Newton's point where it came nearer zero (and stayed within a cell), else the edge's.
        const bool better = moved[i].allFinite() &&
                            std::abs(after[i].value) < std::abs(before[i].value) &&
                            (moved[i] - found[i]).norm() <= 2.0 * h;
        seeds.push_back(better ? moved[i] : found[i]);
    }
}

/// The seeds of an operator's result from its members' candidates (see operators.h): moved onto
/// the result's surface first by `displaced` Newton steps (0 where the surface is a member's),
/// kept where the result is near zero; else all moved by Newton steps and kept where they reach
/// zero; else a sweep of the bounds.
void operator_seeds(const Field& field, Candidates c, int displaced, std::vector<Vec3d>& seeds)
{
    if (!c.complete || c.points.empty())
    {
        return;
    }
    if (displaced > 0)
    {
        project_seeds(field, c.points, 0, displaced);
    }
    if (keep_near_zero(field, c.points, c.slack, seeds) > 0)
    {
        return;
    }
    project_seeds(field, c.points, 0, 4);
    std::fill(c.slack.begin(), c.slack.end(), 0.0);
    if (keep_near_zero(field, c.points, c.slack, seeds) > 0)
    {
        return;
    }
    sweep_seeds(field, seeds);
}

/// Members' samples at one point, on the stack for the usual few members.
class SampleBuffer
{
public:
    explicit SampleBuffer(std::size_t n)
    {
        if (n > stack_.size())
        {
            heap_.resize(n);
            view_ = heap_;
        }
        else
        {
            view_ = std::span<FieldSample>(stack_.data(), n);
        }
    }
    [[nodiscard]] std::span<FieldSample> view() const { return view_; }

private:
    std::array<FieldSample, 8> stack_{};
    std::vector<FieldSample> heap_;
    std::span<FieldSample> view_;
};

} // namespace

// ---------------------------------------------------------------------------------------------

BooleanField::BooleanField(BooleanOp op, std::vector<FieldPtr> members)
    : op_(op), members_(std::move(members))
{
    const char* name = op == BooleanOp::Union          ? "union"
                       : op == BooleanOp::Intersection ? "intersection"
                                                       : "difference";
    require_members(members_, op == BooleanOp::Difference ? 2 : 1, name);
    std::vector<double> costs(members_.size());
    for (std::size_t i = 0; i < members_.size(); ++i)
    {
        costs[i] = members_[i]->cost();
    }
    order_.resize(members_.size());
    std::iota(order_.begin(), order_.end(), std::size_t{0});
    std::stable_sort(order_.begin(), order_.end(),
                     [&costs](std::size_t i, std::size_t j) { return costs[i] < costs[j]; });
    cost_ = summed_cost(members_);
}

FieldSample BooleanField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -infinity, infinity);
}

/// One point's Boolean as a minimum of g_i = s_i f_i: union s_i = 1; intersection s_i = −1
/// (max f = −min −f); difference −1 for the first member, 1 for the rest
/// (max(f_0, −f_i) = −min(−f_0, f_i)). The result is ±min g_i (+ for union), in [lo, hi] where
/// min g_i is in [g_lo, g_hi]. Member i decides only if g_i ≤ the smallest so far (ties go to
/// the earlier member, hence closed ranges), and matters exactly only within [g_lo, g_hi].
class BooleanField::Minimum
{
public:
    Minimum(BooleanOp op, std::size_t members, double lo, double hi)
        : op_(op),
          g_lo_(op == BooleanOp::Union ? lo : -hi),
          g_hi_(op == BooleanOp::Union ? hi : -lo),
          none_(members),
          best_index_(members)
    {}

    [[nodiscard]] double sign_of(std::size_t i) const
    {
        return op_ == BooleanOp::Union || (op_ == BooleanOp::Difference && i > 0) ? 1.0 : -1.0;
    }
    /// The range to ask of member i.
    [[nodiscard]] std::pair<double, double> range_of(std::size_t i) const
    {
        const double cap = std::min(g_hi_, best_g_);
        return sign_of(i) > 0.0 ? std::pair{g_lo_, cap} : std::pair{-cap, -g_lo_};
    }
    void take(std::size_t i, const FieldSample& s)
    {
        const double g = sign_of(i) * s.value;
        if (g < best_g_ || (g == best_g_ && i < best_index_) || best_index_ == none_)
        {
            best_ = s;
            best_g_ = g;
            best_index_ = i;
        }
    }
    /// The chosen member's sample, negated for the subtracted members of a difference.
    [[nodiscard]] FieldSample result() const
    {
        FieldSample out = best_;
        if (op_ == BooleanOp::Difference && best_index_ > 0)
        {
            out.value = -out.value;
            out.gradient = -out.gradient;
        }
        return out;
    }

private:
    BooleanOp op_;
    double g_lo_;
    double g_hi_;
    std::size_t none_;
    FieldSample best_;
    double best_g_ = infinity;
    std::size_t best_index_;
};

FieldSample BooleanField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    Minimum minimum(op_, members_.size(), lo, hi);
    for (const std::size_t i : order_)
    {
        const auto [member_lo, member_hi] = minimum.range_of(i);
        minimum.take(i, members_[i]->evaluate_within(p, member_lo, member_hi));
    }
    return minimum.result();
}

void BooleanField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                   std::span<const double> hi, std::span<FieldSample> out) const
{
    check_within_sizes("BooleanField::evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    parallel_blocks(points.size(), operator_block, [&](std::size_t begin, std::size_t end) {
        const std::size_t n = end - begin;
        std::vector<Minimum> minima;
        minima.reserve(n);
        for (std::size_t j = begin; j < end; ++j)
        {
            minima.emplace_back(op_, members_.size(), lo[j], hi[j]);
        }
        std::vector<double> member_lo(n);
        std::vector<double> member_hi(n);
        std::vector<FieldSample> samples(n);
        for (const std::size_t i : order_)
        {
            for (std::size_t j = 0; j < n; ++j)
            {
                std::tie(member_lo[j], member_hi[j]) = minima[j].range_of(i);
            }
            members_[i]->evaluate_within(points.subspan(begin, n), member_lo, member_hi, samples);
            for (std::size_t j = 0; j < n; ++j)
            {
                minima[j].take(i, samples[j]);
            }
        }
        for (std::size_t j = 0; j < n; ++j)
        {
            out[begin + j] = minima[j].result();
        }
    });
}

double BooleanField::cost() const
{
    return cost_;
}

Aabb BooleanField::bounds() const
{
    Aabb box = members_.front()->bounds();
    if (op_ == BooleanOp::Difference)
    {
        return box;
    }
    for (std::size_t i = 1; i < members_.size(); ++i)
    {
        box = op_ == BooleanOp::Union ? union_of(box, members_[i]->bounds())
                                      : intersection_of(box, members_[i]->bounds());
    }
    return box;
}

void BooleanField::append_seeds(std::vector<Vec3d>& seeds) const
{
    operator_seeds(*this, gather_all(members_), 0, seeds);
}

// ---------------------------------------------------------------------------------------------

SmoothBooleanField::SmoothBooleanField(BooleanOp op, FieldPtr a, FieldPtr b, double radius,
                                       UndefinedPolicy policy)
    : op_(op), a_(std::move(a)), b_(std::move(b)), radius_(radius), policy_(policy)
{
    require_member(a_, "smooth Boolean");
    require_member(b_, "smooth Boolean");
    if (!(radius > 0.0) || !std::isfinite(radius))
    {
        throw InvalidInput("smooth Boolean: the blend radius must be positive and finite, got " +
                           std::to_string(radius));
    }
    b_first_ = b_->cost() < a_->cost();
    const std::array<FieldPtr, 2> members = {a_, b_};
    cost_ = summed_cost(members);
}

FieldSample SmoothBooleanField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -infinity, infinity);
}

// As a smooth minimum of g_a = s_a f_a and g_b = s_b f_b (s = 1 for union; −1 for
// intersection; difference: s_a = −1, s_b = 1), sign · (min − k h²/4) in [lo, hi] needs min in
// [g_lo, g_hi + k/4], and both exactly where |g_a − g_b| < k: the cheaper member first within
// [g_lo, g_hi + 5k/4], then the other also within k of the first.

double SmoothBooleanField::sign_of(bool b) const
{
    const double sign = op_ == BooleanOp::Union ? 1.0 : -1.0;
    return b && op_ == BooleanOp::Difference ? 1.0 : sign;
}

std::pair<double, double> SmoothBooleanField::range_of(bool b, double lo, double hi,
                                                       const FieldSample* first) const
{
    const double g_lo = op_ == BooleanOp::Union ? lo : -hi;
    double cap = (op_ == BooleanOp::Union ? hi : -lo) + 1.25 * radius_;
    if (first != nullptr)
    {
        cap = std::min(cap, sign_of(!b) * first->value + radius_);
    }
    return sign_of(b) > 0.0 ? std::pair{g_lo, cap} : std::pair{-cap, -g_lo};
}

FieldSample SmoothBooleanField::combine(const FieldSample& sa, FieldSample sb) const
{
    if (op_ == BooleanOp::Difference)
    {
        sb.value = -sb.value;
        sb.gradient = -sb.gradient;
    }
    // Work on the minimum: the intersection is −smin(−a, −b).
    const double sign = op_ == BooleanOp::Union ? 1.0 : -1.0;
    const double a = sign * sa.value;
    const double b = sign * sb.value;
    const bool a_smaller = a <= b;
    const FieldSample& low = a_smaller ? sa : sb;
    const FieldSample& high = a_smaller ? sb : sa;
    const double h = std::max(radius_ - std::abs(a - b), 0.0) / radius_;
    if (h <= 0.0)
    {
        return low;
    }
    FieldSample out;
    out.value = low.value - sign * 0.25 * radius_ * h * h;
    out.gradient = (1.0 - 0.5 * h) * low.gradient + 0.5 * h * high.gradient;
    out.defined = usable(sa, policy_) && usable(sb, policy_);
    return out;
}

FieldSample SmoothBooleanField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    const bool b_first = b_first_;
    const Field& first = b_first ? *b_ : *a_;
    const Field& second = b_first ? *a_ : *b_;
    const auto [first_lo, first_hi] = range_of(b_first, lo, hi, nullptr);
    const FieldSample f = first.evaluate_within(p, first_lo, first_hi);
    const auto [second_lo, second_hi] = range_of(!b_first, lo, hi, &f);
    const FieldSample g = second.evaluate_within(p, second_lo, second_hi);
    return b_first ? combine(g, f) : combine(f, g);
}

void SmoothBooleanField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                         std::span<const double> hi,
                                         std::span<FieldSample> out) const
{
    check_within_sizes("SmoothBooleanField::evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    const bool b_first = b_first_;
    const Field& first = b_first ? *b_ : *a_;
    const Field& second = b_first ? *a_ : *b_;
    parallel_blocks(points.size(), operator_block, [&](std::size_t begin, std::size_t end) {
        const std::size_t n = end - begin;
        const std::span<const Vec3d> block = points.subspan(begin, n);
        std::vector<double> member_lo(n);
        std::vector<double> member_hi(n);
        std::vector<FieldSample> f(n);
        std::vector<FieldSample> g(n);
        for (std::size_t j = 0; j < n; ++j)
        {
            std::tie(member_lo[j], member_hi[j]) =
                range_of(b_first, lo[begin + j], hi[begin + j], nullptr);
        }
        first.evaluate_within(block, member_lo, member_hi, f);
        for (std::size_t j = 0; j < n; ++j)
        {
            std::tie(member_lo[j], member_hi[j]) =
                range_of(!b_first, lo[begin + j], hi[begin + j], &f[j]);
        }
        second.evaluate_within(block, member_lo, member_hi, g);
        for (std::size_t j = 0; j < n; ++j)
        {
            out[begin + j] = b_first ? combine(g[j], f[j]) : combine(f[j], g[j]);
        }
    });
}

double SmoothBooleanField::cost() const
{
    return cost_;
}

Aabb SmoothBooleanField::bounds() const
{
    switch (op_)
    {
        case BooleanOp::Union:
            return grown(union_of(a_->bounds(), b_->bounds()), 0.25 * radius_);
        case BooleanOp::Intersection:
            return intersection_of(a_->bounds(), b_->bounds());
        case BooleanOp::Difference:
            break;
    }
    return a_->bounds();
}

void SmoothBooleanField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const std::array<FieldPtr, 2> members = {a_, b_};
    operator_seeds(*this, gather_all(members), 0, seeds);
}

// ---------------------------------------------------------------------------------------------

BlendField::BlendField(BlendKind kind, std::vector<FieldPtr> members, std::vector<double> alphas,
                       double beta, UndefinedPolicy policy)
    : kind_(kind),
      members_(std::move(members)),
      alphas_(std::move(alphas)),
      beta_(kind == BlendKind::SuperElliptic ? beta : 1.0),
      policy_(policy)
{
    require_members(members_, 1, "blend");
    if (alphas_.size() == 1 && members_.size() > 1)
    {
        alphas_.assign(members_.size(), alphas_.front());
    }
    if (alphas_.size() != members_.size())
    {
        throw InvalidInput("blend: " + std::to_string(alphas_.size()) + " α parameters for " +
                           std::to_string(members_.size()) + " fields");
    }
    for (const double alpha : alphas_)
    {
        if (!(alpha > 0.0) || !std::isfinite(alpha))
        {
            throw InvalidInput("blend: α must be positive and finite, got " +
                               std::to_string(alpha));
        }
    }
    if (kind == BlendKind::SuperElliptic && (!(beta >= 1.0) || !std::isfinite(beta)))
    {
        throw InvalidInput("blend: the super-elliptic exponent β must be ≥ 1 and finite, got " +
                           std::to_string(beta));
    }
    alpha_max_ = *std::max_element(alphas_.begin(), alphas_.end());
    cost_ = summed_cost(members_);
}

FieldSample BlendField::evaluate(const Vec3d& p) const
{
    const std::size_t n = members_.size();
    SampleBuffer buffer(n);
    const std::span<FieldSample> s = buffer.view();
    for (std::size_t i = 0; i < n; ++i)
    {
        s[i] = members_[i]->evaluate(p);
    }
    FieldSample out;
    out.defined = true;
    const double inv = 1.0 / alpha_max_;

    if (kind_ == BlendKind::Hyperbolic)
    {
        double product = 1.0;
        std::size_t lowest = 0;
        for (std::size_t i = 0; i < n; ++i)
        {
            const double q = alphas_[i] * s[i].value;
            product *= q;
            if (q < alphas_[lowest] * s[lowest].value)
            {
                lowest = i;
            }
            out.defined = out.defined && usable(s[i], policy_);
        }
        const double q_min = alphas_[lowest] * s[lowest].value;
        if (q_min <= 0.0)
        {
            // Inside a member: continue as min q − 1, continuous with Π q − 1 at q_min = 0.
            out.value = (q_min - 1.0) * inv;
            out.gradient = alphas_[lowest] * inv * s[lowest].gradient;
            return out;
        }
        out.value = (product - 1.0) * inv;
        for (std::size_t i = 0; i < n; ++i)
        {
            const double q = alphas_[i] * s[i].value;
            out.gradient += (product / q) * alphas_[i] * inv * s[i].gradient;
        }
        return out;
    }

    // Linear (β = 1) and super-elliptic: potentials p_i = 1 − α_i f_i, clamped at 0.
    double p_max = -std::numeric_limits<double>::infinity();
    std::size_t arg_max = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > p_max)
        {
            p_max = potential;
            arg_max = i;
        }
    }
    if (!(p_max > 0.0))
    {
        // Beyond every range: B = 1 is flat there; continue as min α_i f_i = 1 − max p_i.
        out.value = (1.0 - p_max) * inv;
        out.gradient = alphas_[arg_max] * inv * s[arg_max].gradient;
        out.defined = usable(s[arg_max], policy_);
        return out;
    }
    // S = (Σ p_i^β)^{1/β}, computed as p_max·(Σ (p_i/p_max)^β)^{1/β} so that it cannot overflow.
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > 0.0)
        {
            sum += beta_ == 1.0 ? potential / p_max : std::pow(potential / p_max, beta_);
            out.defined = out.defined && usable(s[i], policy_);
        }
    }
    const double norm = beta_ == 1.0 ? sum : std::pow(sum, 1.0 / beta_);
    const double big_s = p_max * norm;
    out.value = (1.0 - big_s) * inv;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > 0.0)
        {
            // ∂S/∂p_i = (p_i/S)^{β−1}; ∂p_i/∂x = −α_i ∇f_i; value = (1 − S)/α_max.
            const double weight = beta_ == 1.0 ? 1.0 : std::pow(potential / big_s, beta_ - 1.0);
            out.gradient += weight * alphas_[i] * inv * s[i].gradient;
        }
    }
    return out;
}

double BlendField::cost() const
{
    return cost_;
}

Aabb BlendField::bounds() const
{
    Aabb box;
    for (const FieldPtr& m : members_)
    {
        box = union_of(box, m->bounds());
    }
    const double range = 1.0 / *std::min_element(alphas_.begin(), alphas_.end());
    return grown(box, range);
}

void BlendField::append_seeds(std::vector<Vec3d>& seeds) const
{
    operator_seeds(*this, gather_all(members_), kind_ == BlendKind::Hyperbolic ? 4 : 0, seeds);
}

// ---------------------------------------------------------------------------------------------

OffsetField::OffsetField(FieldPtr member, double distance, UndefinedPolicy policy)
    : member_(std::move(member)), distance_(distance), policy_(policy)
{
    require_member(member_, "offset");
    if (!std::isfinite(distance))
    {
        throw InvalidInput("offset: the distance must be finite");
    }
    cost_ = 1.0 + member_->cost();
}

FieldSample OffsetField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -infinity, infinity);
}

FieldSample OffsetField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    const auto [member_lo, member_hi] = shifted_range(lo, hi, distance_);
    return offset_of(member_->evaluate_within(p, member_lo, member_hi), distance_, policy_);
}

void OffsetField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                  std::span<const double> hi, std::span<FieldSample> out) const
{
    unary_batch(
        *member_, points, lo, hi, out,
        [this](double l, double h) { return shifted_range(l, h, distance_); },
        [this](const FieldSample& s) { return offset_of(s, distance_, policy_); });
}

double OffsetField::cost() const
{
    return cost_;
}

Aabb OffsetField::bounds() const
{
    return grown(member_->bounds(), distance_);
}

void OffsetField::append_seeds(std::vector<Vec3d>& seeds) const
{
    operator_seeds(*this, gather_all(std::span(&member_, 1)), distance_ != 0.0 ? 3 : 0, seeds);
}

// ---------------------------------------------------------------------------------------------

ShellField::ShellField(FieldPtr member, double thickness, UndefinedPolicy policy)
    : member_(std::move(member)), thickness_(thickness), policy_(policy)
{
    require_member(member_, "shell");
    if (!(thickness > 0.0) || !std::isfinite(thickness))
    {
        throw InvalidInput("shell: the thickness must be positive and finite, got " +
                           std::to_string(thickness));
    }
    cost_ = 1.0 + member_->cost();
}

FieldSample ShellField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -infinity, infinity);
}

FieldSample ShellField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    const auto [member_lo, member_hi] = shell_range(lo, hi, thickness_);
    return shell_of(member_->evaluate_within(p, member_lo, member_hi), thickness_, policy_);
}

void ShellField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                 std::span<const double> hi, std::span<FieldSample> out) const
{
    unary_batch(
        *member_, points, lo, hi, out,
        [this](double l, double h) { return shell_range(l, h, thickness_); },
        [this](const FieldSample& s) { return shell_of(s, thickness_, policy_); });
}

double ShellField::cost() const
{
    return cost_;
}

Aabb ShellField::bounds() const
{
    return grown(member_->bounds(), 0.5 * thickness_);
}

void ShellField::append_seeds(std::vector<Vec3d>& seeds) const
{
    // The two surfaces are separate pieces: push every member seed to both sides.
    const Candidates base = gather_all(std::span(&member_, 1));
    if (!base.complete)
    {
        return;
    }
    std::vector<FieldSample> samples(base.points.size());
    member_->evaluate(base.points, samples);
    Candidates c;
    c.points.reserve(2 * base.points.size());
    for (std::size_t i = 0; i < base.points.size(); ++i)
    {
        const double g = samples[i].gradient.norm();
        if (!(g > 0.0) || !samples[i].gradient.allFinite())
        {
            c.points.push_back(base.points[i]);
            c.slack.push_back(base.slack[i]);
            continue;
        }
        const Vec3d step = (0.5 * thickness_ / g) * samples[i].gradient;
        for (const Vec3d& p : {Vec3d(base.points[i] + step), Vec3d(base.points[i] - step)})
        {
            c.points.push_back(p);
            c.slack.push_back(base.slack[i]);
        }
    }
    operator_seeds(*this, std::move(c), 2, seeds);
}

// ---------------------------------------------------------------------------------------------

MorphField::MorphField(FieldPtr from, FieldPtr to, double t, UndefinedPolicy policy)
    : from_(std::move(from)), to_(std::move(to)), t_(t), policy_(policy)
{
    require_member(from_, "morph");
    require_member(to_, "morph");
    if (!(t >= 0.0 && t <= 1.0))
    {
        throw InvalidInput("morph: t must be in [0, 1], got " + std::to_string(t));
    }
    if (intersection_of(from_->bounds(), to_->bounds()).is_empty())
    {
        throw InvalidInput(
            "morph: the bounds of the two fields do not overlap, so the in-between shapes "
            "would be empty");
    }
    const std::array<FieldPtr, 2> members = {from_, to_};
    cost_ = summed_cost(members);
}

FieldSample MorphField::evaluate(const Vec3d& p) const
{
    if (t_ == 0.0)
    {
        FieldSample s = from_->evaluate(p);
        s.defined = usable(s, policy_);
        return s;
    }
    if (t_ == 1.0)
    {
        FieldSample s = to_->evaluate(p);
        s.defined = usable(s, policy_);
        return s;
    }
    const FieldSample a = from_->evaluate(p);
    const FieldSample b = to_->evaluate(p);
    return {.value = (1.0 - t_) * a.value + t_ * b.value,
            .gradient = (1.0 - t_) * a.gradient + t_ * b.gradient,
            .defined = usable(a, policy_) && usable(b, policy_)};
}

double MorphField::cost() const
{
    return cost_;
}

Aabb MorphField::bounds() const
{
    if (t_ == 0.0)
    {
        return from_->bounds();
    }
    if (t_ == 1.0)
    {
        return to_->bounds();
    }
    return union_of(from_->bounds(), to_->bounds());
}

void MorphField::append_seeds(std::vector<Vec3d>& seeds) const
{
    std::vector<FieldPtr> members;
    if (t_ < 1.0)
    {
        members.push_back(from_);
    }
    if (t_ > 0.0)
    {
        members.push_back(to_);
    }
    operator_seeds(*this, gather_all(members), t_ > 0.0 && t_ < 1.0 ? 4 : 0, seeds);
}

// ---------------------------------------------------------------------------------------------

namespace {

/// What one thread remembers of the last batch asked of one SharedField.
struct Remembered
{
    std::vector<Vec3d> points;
    std::vector<double> lo;
    std::vector<double> hi;
    std::vector<FieldSample> samples;
};

/// The SharedFields that exist, and how many have ceased to: a thread drops what it remembers of
/// the dead ones when it holds more than `purge_above` batches and some have died since it last
/// looked, so threads that outlive scenes do not keep their batches.
struct Registry
{
    std::mutex mutex;
    std::unordered_set<std::uint64_t> live;
    std::atomic<std::uint64_t> deaths{0};
};

Registry& registry()
{
    static Registry r;
    return r;
}

constexpr std::size_t purge_above = 64;

/// The batches remembered by this thread, by SharedField id.
std::unordered_map<std::uint64_t, Remembered>& remembered()
{
    thread_local std::unordered_map<std::uint64_t, Remembered> map;
    thread_local std::uint64_t deaths_seen = 0;
    if (map.size() > purge_above)
    {
        Registry& r = registry();
        const std::uint64_t deaths = r.deaths.load(std::memory_order_acquire);
        if (deaths != deaths_seen)
        {
            const std::lock_guard lock(r.mutex);
            std::erase_if(map, [&r](const auto& entry) { return !r.live.contains(entry.first); });
            deaths_seen = deaths;
        }
    }
    return map;
}

bool same_point(const Vec3d& a, const Vec3d& b)
{
    return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0;
}

std::atomic<std::uint64_t> next_shared_id{1};

} // namespace

SharedField::SharedField(FieldPtr member) : member_(std::move(member)), id_(next_shared_id++)
{
    require_member(member_, "shared field");
    {
        const std::lock_guard lock(registry().mutex);
        registry().live.insert(id_);
    }
    cost_ = member_->cost();
    bounds_ = member_->bounds();
}

SharedField::~SharedField()
{
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    r.live.erase(id_);
    r.deaths.fetch_add(1, std::memory_order_release);
}

FieldSample SharedField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -infinity, infinity);
}

FieldSample SharedField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    FieldSample out;
    evaluate_within(std::span(&p, 1), std::span(&lo, 1), std::span(&hi, 1), std::span(&out, 1));
    return out;
}

void SharedField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                  std::span<const double> hi, std::span<FieldSample> out) const
{
    check_within_sizes("SharedField::evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    const std::size_t n = points.size();
    if (n > operator_block)
    {
        // Only the top of an evaluation asks for more at once, and it asks once.
        member_->evaluate_within(points, lo, hi, out);
        return;
    }
    Remembered& r = remembered()[id_];
    std::vector<std::size_t> missing;
    if (r.points.size() == n &&
        std::equal(points.begin(), points.end(), r.points.begin(), same_point))
    {
        for (std::size_t i = 0; i < n; ++i)
        {
            if (r.lo[i] <= lo[i] && r.hi[i] >= hi[i])
            {
                out[i] = r.samples[i];
            }
            else
            {
                missing.push_back(i);
            }
        }
        if (missing.empty())
        {
            return;
        }
    }
    else
    {
        member_->evaluate_within(points, lo, hi, out);
        // Looked up again: the member's evaluation may have remembered other shared fields
        // meanwhile (the map keeps its elements in place, but may drop dead fields' ones).
        Remembered& fresh = remembered()[id_];
        fresh.points.assign(points.begin(), points.end());
        fresh.lo.assign(lo.begin(), lo.end());
        fresh.hi.assign(hi.begin(), hi.end());
        fresh.samples.assign(out.begin(), out.end());
        return;
    }
    std::vector<Vec3d> at(missing.size());
    std::vector<double> at_lo(missing.size());
    std::vector<double> at_hi(missing.size());
    std::vector<FieldSample> samples(missing.size());
    for (std::size_t j = 0; j < missing.size(); ++j)
    {
        at[j] = points[missing[j]];
        at_lo[j] = lo[missing[j]];
        at_hi[j] = hi[missing[j]];
    }
    member_->evaluate_within(at, at_lo, at_hi, samples);
    Remembered& again = remembered()[id_];
    const bool still = again.points.size() == n;
    for (std::size_t j = 0; j < missing.size(); ++j)
    {
        const std::size_t i = missing[j];
        out[i] = samples[j];
        if (still)
        {
            again.lo[i] = at_lo[j];
            again.hi[i] = at_hi[j];
            again.samples[i] = samples[j];
        }
    }
}

double SharedField::cost() const
{
    return cost_;
}

Aabb SharedField::bounds() const
{
    return bounds_;
}

void SharedField::append_seeds(std::vector<Vec3d>& seeds) const
{
    std::call_once(seeds_once_, [this] { member_->append_seeds(seeds_); });
    seeds.insert(seeds.end(), seeds_.begin(), seeds_.end());
}

std::shared_ptr<const Field> make_shared_node(FieldPtr member)
{
    if (std::dynamic_pointer_cast<const SharedField>(member) != nullptr)
    {
        return member;
    }
    return std::make_shared<const SharedField>(std::move(member));
}

// ---------------------------------------------------------------------------------------------

std::shared_ptr<const Field> make_union(std::vector<FieldPtr> members)
{
    return std::make_shared<const BooleanField>(BooleanOp::Union, std::move(members));
}

std::shared_ptr<const Field> make_intersection(std::vector<FieldPtr> members)
{
    return std::make_shared<const BooleanField>(BooleanOp::Intersection, std::move(members));
}

std::shared_ptr<const Field> make_difference(FieldPtr a, FieldPtr b)
{
    return std::make_shared<const BooleanField>(BooleanOp::Difference,
                                                std::vector<FieldPtr>{std::move(a), std::move(b)});
}

std::shared_ptr<const Field> make_smooth_union(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Union, std::move(a), std::move(b),
                                                      radius);
}

std::shared_ptr<const Field> make_smooth_intersection(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Intersection, std::move(a),
                                                      std::move(b), radius);
}

std::shared_ptr<const Field> make_smooth_difference(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Difference, std::move(a),
                                                      std::move(b), radius);
}

std::shared_ptr<const Field> make_blend(BlendKind kind, std::vector<FieldPtr> members, double range,
                                        double beta)
{
    if (!(range > 0.0) || !std::isfinite(range))
    {
        throw InvalidInput("blend: the blend range must be positive and finite, got " +
                           std::to_string(range));
    }
    return std::make_shared<const BlendField>(kind, std::move(members),
                                              std::vector<double>{1.0 / range}, beta);
}

std::shared_ptr<const Field> make_offset(FieldPtr member, double distance)
{
    return std::make_shared<const OffsetField>(std::move(member), distance);
}

std::shared_ptr<const Field> make_shell(FieldPtr member, double thickness)
{
    return std::make_shared<const ShellField>(std::move(member), thickness);
}

std::shared_ptr<const Field> make_morph(FieldPtr from, FieldPtr to, double t)
{
    return std::make_shared<const MorphField>(std::move(from), std::move(to), t);
}

} // namespace pointform
