// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/scans.h"

#include "pointform/io/io.h"

#include <filesystem>
#include <system_error>
#include <utility>

namespace pointform {

ScanLoading::ScanLoading(ScanOptions options) : options_(std::move(options)) {}

std::shared_ptr<const PointField> ScanLoading::load(const std::string& path)
{
    std::error_code error;
    std::string key = std::filesystem::weakly_canonical(path, error).string();
    if (error)
        key = path;
    const auto it = index_.find(key);
    if (it != index_.end())
        return scans_[it->second].field;
    SurfelsFromSamples made = surfels_from_samples(read_point_cloud(path), options_.surfels);
    LoadedScan scan;
    scan.path = path;
    scan.samples = made.surfels.size();
    scan.estimated_normals = made.estimated_normals;
    scan.unoriented = made.unoriented;
    scan.field = std::make_shared<const PointField>(std::move(made.surfels), options_.field);
    index_.emplace(key, scans_.size());
    scans_.push_back(std::move(scan));
    return scans_.back().field;
}

ScanLoader ScanLoading::loader()
{
    return [this](const std::string& path) -> std::shared_ptr<const Field> {
        return load(path);
    };
}

} // namespace pointform
