// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/field.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

namespace pointform {

Field::~Field() = default;

void Field::evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const
{
    PF_ASSERT(points.size() == out.size());
    parallel_blocks(points.size(), 1024, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            out[i] = evaluate(points[i]);
        }
    });
}

void Field::append_seeds(std::vector<Vec3d>& /*seeds*/) const {}

} // namespace pointform
