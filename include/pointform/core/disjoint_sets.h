// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

namespace pointform {

/// \brief Union-find over the elements 0..n-1 (n < 2^32), with path halving and union by size.
///
/// Which element represents a set depends on the order of unions; membership does not.
class DisjointSets
{
public:
    explicit DisjointSets(std::size_t n) : parent_(n), size_(n, 1)
    {
        std::iota(parent_.begin(), parent_.end(), 0U);
    }

    /// \brief The representative of x's set.
    std::size_t find(std::size_t x)
    {
        auto i = static_cast<std::uint32_t>(x);
        while (parent_[i] != i)
        {
            i = parent_[i] = parent_[parent_[i]];
        }
        return i;
    }

    /// \brief Joins the sets of a and b; false if they were one already.
    bool unite(std::size_t a, std::size_t b)
    {
        auto ra = static_cast<std::uint32_t>(find(a));
        auto rb = static_cast<std::uint32_t>(find(b));
        if (ra == rb)
        {
            return false;
        }
        if (size_[ra] < size_[rb])
        {
            std::swap(ra, rb);
        }
        parent_[rb] = ra;
        size_[ra] += size_[rb];
        return true;
    }

private:
    std::vector<std::uint32_t> parent_;
    std::vector<std::uint32_t> size_;
};

} // namespace pointform
