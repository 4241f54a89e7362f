// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/progress.h"

#include "pointform/core/error.h"

#include <string>

namespace pointform {

ProgressReporter::ProgressReporter(const ProgressCallback& callback, std::string_view stage)
    : callback_(callback ? &callback : nullptr), stage_(stage)
{}

void ProgressReporter::update(double done, double total)
{
    if (callback_ == nullptr || total <= 0.0)
        return;
    const double fraction = done / total;
    // Report at most about every percent so that callers may call this from hot loops.
    if (fraction - last_reported_ < 0.01 && fraction < 1.0)
        return;
    last_reported_ = fraction;
    if (!(*callback_)(stage_, fraction))
        throw Cancelled("cancelled during " + std::string(stage_));
}

void ProgressReporter::finish()
{
    update(1.0, 1.0);
}

} // namespace pointform
