// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/memory.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief k nearest neighbours of N query points as a flat N by k table (row i lists the
/// neighbours of query i, nearest first) with the matching squared distances, or only each
/// row's farthest one (KnnOptions::farthest_distance_only: 4 bytes a row instead of 4 k, for
/// callers that need the k-th distance alone, such as the influence radius).
struct KnnTable
{
    KnnTable() = default; // not an aggregate: `{.k = 16}` means options, never a table

    std::size_t k = 0;
    /// N*k, row-major. Its pages are first written by the search that fills it (knn_batch()).
    FilledLaterVector<std::uint32_t> indices;
    /// N*k, row-major, non-decreasing within a row; or N, each row's farthest.
    FilledLaterVector<float> squared_distances;

    [[nodiscard]] std::size_t rows() const { return k == 0 ? 0 : indices.size() / k; }
    [[nodiscard]] std::span<const std::uint32_t> neighbors(std::size_t i) const
    {
        return {indices.data() + i * k, k};
    }
    /// \pre has_all_distances()
    [[nodiscard]] std::span<const float> distances2(std::size_t i) const
    {
        return {squared_distances.data() + i * k, k};
    }
    /// \brief The squared distance to row i's farthest (k-th) neighbour, in either layout.
    [[nodiscard]] float farthest2(std::size_t i) const
    {
        return has_all_distances() ? squared_distances[i * k + k - 1] : squared_distances[i];
    }
    [[nodiscard]] bool has_all_distances() const
    {
        return squared_distances.size() == indices.size();
    }
};

/// \brief Checks a neighbour table handed to a public function (it may have been built by hand):
/// `rows` rows of k > 0 columns (unless rows = 0), as many squared distances as indices, every
/// index below `points`. Linear in the table, so it costs little next to any use of it.
/// \throw InvalidInput naming `function` and what is wrong
void check_knn_table(const KnnTable& table, std::size_t rows, std::size_t points,
                     const char* function);

/// \brief check_knn_table() without the pass over the indices, for a caller that checks each
/// row's indices as it reads them (one memory pass instead of two).
void check_knn_table_shape(const KnnTable& table, std::size_t rows, const char* function);

/// \brief Throws InvalidInput naming `function`, the neighbour `index` and its `row`, out of
/// range for `points` points (check_knn_table(), check_knn_row()).
[[noreturn]] void throw_knn_index_out_of_range(std::uint32_t index, std::size_t row,
                                               std::size_t points, const char* function);

/// \brief The per-row check of such a caller: every index of row `row` below `points`. Inline:
/// it runs once a row in loops over millions of them.
/// \throw InvalidInput as check_knn_table() does
inline void check_knn_row(const KnnTable& table, std::size_t row, std::size_t points,
                          const char* function)
{
    for (const std::uint32_t index : table.neighbors(row))
        if (index >= points)
            throw_knn_index_out_of_range(index, row, points, function);
}

/// \brief Variable-size neighbourhoods in compressed sparse row form: the neighbours of query i
/// are indices[offsets[i] .. offsets[i+1]), nearest first.
struct RadiusTable
{
    RadiusTable() = default;

    std::vector<std::size_t> offsets; ///< N+1
    std::vector<std::uint32_t> indices;
    std::vector<float> squared_distances;

    [[nodiscard]] std::size_t rows() const { return offsets.empty() ? 0 : offsets.size() - 1; }
    [[nodiscard]] std::span<const std::uint32_t> neighbors(std::size_t i) const
    {
        return {indices.data() + offsets[i], offsets[i + 1] - offsets[i]};
    }
    [[nodiscard]] std::span<const float> distances2(std::size_t i) const
    {
        return {squared_distances.data() + offsets[i], offsets[i + 1] - offsets[i]};
    }
};

} // namespace pointform
