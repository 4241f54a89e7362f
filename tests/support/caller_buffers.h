// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// What the caller-buffer tests of every module share.

#pragma once

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"

#include <gtest/gtest.h>

#include <string>

namespace pointform::test {

/// Runs `call`, expecting InvalidInput whose message holds `function` and `buffer`.
template <typename Call>
void expect_rejected(const Call& call, const std::string& function, const std::string& buffer)
{
    try
    {
        call();
        ADD_FAILURE() << function << " accepted a " << buffer << " of the wrong size";
    }
    catch (const InvalidInput& e)
    {
        const std::string what = e.what();
        EXPECT_NE(what.find(function), std::string::npos) << what;
        EXPECT_NE(what.find(buffer), std::string::npos) << what;
    }
}

/// 3000 samples of the torus, made once.
inline const PointCloud& buffer_test_torus()
{
    static const PointCloud cloud = sample_shape(Shape::Torus, {.count = 3000, .seed = 4});
    return cloud;
}

} // namespace pointform::test
