// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/hermite/surfels.h"

#include <string>

namespace pointform::cli {

/// \brief Reads samples and makes them surfels (surfels_from_samples()) with `progress`; the
/// library's InvalidInput gets the file's path in front.
[[nodiscard]] SurfelsFromSamples load_surfels(const std::string& path,
                                              SurfelsFromSamplesOptions options,
                                              const ProgressCallback& progress);

/// \brief Warns on stderr that `unoriented` samples of `path` (no usable normal) were left out;
/// says nothing when there were none.
void warn_unoriented(const std::string& path, std::size_t unoriented);

/// \brief Warns on stderr that `isolated` samples of `path` (alone, far from the rest),
/// `off_surface` ones (standing off the surface of their nearest) and `copies` (at the very place
/// of an earlier sample) were left out; says nothing of none.
void warn_isolated(const std::string& path, std::size_t isolated, std::size_t copies,
                   std::size_t off_surface);

} // namespace pointform::cli
