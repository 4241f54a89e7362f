// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <functional>
#include <string_view>

namespace pointform {

/// \brief Called by long-running algorithms as they advance. The library never prints: the
/// caller (the CLI, a GUI, a script) decides how to show progress.
/// \param stage     short name of the current stage ("kNN", "orientation", ...)
/// \param fraction  progress of that stage in [0, 1]
/// \return false to ask the algorithm to stop; it then throws pointform::Cancelled.
using ProgressCallback = std::function<bool(std::string_view stage, double fraction)>;

/// \brief Reports progress through an optional callback, throttled so that hot loops can call
/// `update` often. Not thread-safe: call it from one thread at a time (parallel_blocks does).
class ProgressReporter
{
public:
    ProgressReporter(const ProgressCallback& callback, std::string_view stage);

    /// \brief Reports `done / total` for this stage; throws Cancelled if the callback says stop.
    void update(double done, double total);
    /// \brief Reports the stage as complete.
    void finish();

private:
    const ProgressCallback* callback_;
    std::string_view stage_;
    double last_reported_ = -1.0;
};

} // namespace pointform
