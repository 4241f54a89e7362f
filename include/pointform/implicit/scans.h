// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/hermite/surfels.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/scene.h"

#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief How ScanLoading makes the field of a scan file.
struct ScanOptions
{
    /// Samples to surfels (surfels_from_samples()); its progress reports the loading.
    SurfelsFromSamplesOptions surfels;
    /// The point field of the surfels.
    PointFieldOptions field;
};

/// \brief A scan loaded for a scene, once.
struct LoadedScan
{
    std::string path;               ///< as the scene resolved it
    std::size_t samples = 0;        ///< surfels in its field
    bool estimated_normals = false; ///< the file had no normals, or reestimate
    std::size_t unoriented = 0;     ///< samples left out for want of a usable normal
    std::size_t isolated = 0;       ///< samples left out as alone far from the rest
    std::size_t off_surface = 0;    ///< samples left out as standing off the surface
    std::size_t copies = 0;         ///< samples left out at the very place of an earlier one
    std::shared_ptr<const PointField> field;
};

/// \brief Loads the scans of scenes (`scan("file")`, SceneOptions::load_scan): reads the file
/// (read_point_cloud()), makes its surfels (surfels_from_samples()) and their PointField, once
/// per file (paths that resolve to the same file share one field).
///
///     ScanLoading scans({.surfels = {.k = 16}});
///     const Scene scene = read_scene("bunny.pf", scans.loader());
///
/// Not copyable or movable: loader() refers to it, so it must outlive the scenes it loads for.
class ScanLoading
{
public:
    explicit ScanLoading(ScanOptions options = {});
    ScanLoading(const ScanLoading&) = delete;
    ScanLoading& operator=(const ScanLoading&) = delete;

    /// \brief The field of the scan at `path`, loaded on first use.
    /// \throw IoError if the file cannot be read; InvalidInput as surfels_from_samples()
    [[nodiscard]] std::shared_ptr<const PointField> load(const std::string& path);

    /// \brief load() as a ScanLoader for parse_scene() and read_scene().
    [[nodiscard]] ScanLoader loader();

    /// \brief The scans loaded so far, in the order they were first loaded.
    [[nodiscard]] const std::vector<LoadedScan>& scans() const { return scans_; }

private:
    ScanOptions options_;
    std::vector<LoadedScan> scans_;
    std::map<std::string, std::size_t> index_; // canonical path -> scans_
};

/// \brief How load_scene_argument() took an argument.
enum class SceneArgumentKind
{
    Expression, ///< not an existing file: parsed as a scene expression
    SceneFile,  ///< an existing file whose extension is not a point format
    Scan,       ///< an existing point or mesh file (.ply, .xyz, .las, ...): its point field
};

[[nodiscard]] std::string_view to_string(SceneArgumentKind kind);

/// \brief A scene argument's field and how it was taken.
struct LoadedScene
{
    std::shared_ptr<const Field> field;
    SceneArgumentKind kind = SceneArgumentKind::Expression;
};

/// \brief A scene from one argument, as `pointform model` takes it: the point field of a scan
/// file (.ply, .xyz, .las, ...), a scene file (read_scene(): any other existing file; its scans
/// resolve against its folder), or else a scene expression (parse_scene(), named "expression"
/// in messages). Scans load through `scans`, so arguments share them.
/// \throw IoError for a file that cannot be read; InvalidInput as parse_scene()
[[nodiscard]] LoadedScene load_scene_argument(const std::string& argument, ScanLoading& scans);

} // namespace pointform
