// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/scans.h"

#include "pointform/core/error.h"
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
    scan.isolated = made.isolated;
    scan.off_surface = made.off_surface;
    scan.copies = made.copies;
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

std::string_view to_string(SceneArgumentKind kind)
{
    switch (kind)
    {
        case SceneArgumentKind::Expression:
            return "expression";
        case SceneArgumentKind::SceneFile:
            return "scene file";
        case SceneArgumentKind::Scan:
            return "scan";
    }
    return "?";
}

namespace {

SceneArgumentKind classify(const std::string& argument)
{
    if (!looks_like_file(argument))
        return SceneArgumentKind::Expression;
    try
    {
        (void)format_from_extension(argument);
        return SceneArgumentKind::Scan;
    }
    catch (const IoError&)
    {
        return SceneArgumentKind::SceneFile;
    }
}

} // namespace

LoadedScene load_scene_argument(const std::string& argument, ScanLoading& scans)
{
    LoadedScene loaded;
    loaded.kind = classify(argument);
    switch (loaded.kind)
    {
        case SceneArgumentKind::Scan:
            loaded.field = scans.load(argument);
            break;
        case SceneArgumentKind::SceneFile:
            loaded.field = read_scene(argument, scans.loader()).field;
            break;
        case SceneArgumentKind::Expression:
            loaded.field =
                parse_scene(argument, {.source_name = "expression", .load_scan = scans.loader()})
                    .field;
            break;
    }
    return loaded;
}

} // namespace pointform
