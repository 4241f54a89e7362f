// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief What `pointform view` serves: the data of the one file named on its command line,
/// encoded once at start-up for the data endpoints (docs/viewer.md), and the HTTP server
/// (cpp-httplib) that answers GET requests for a fixed list of names. No path from a request
/// ever reaches the file system: the page's files are read into memory before serving.

#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace pointform::cli {

/// \brief The file a viewer shows, read before the server starts.
struct ViewData
{
    enum class Kind
    {
        Hierarchy, ///< a .pfh file: every level
        Mesh,      ///< a triangle mesh: one level, drawn shaded
        Points     ///< a point cloud (or surfels): drawn as points
    };
    Kind kind = Kind::Points;
    std::string name;                      ///< the file's name (no directories)
    std::optional<MultiresMesh> hierarchy; ///< Hierarchy: its levels
    TriMesh mesh;                          ///< Mesh: the mesh, served as the only level 0
    PointCloud points;                     ///< Points: the points

    /// \brief Levels served by /api/level: the hierarchy's, 1 for a mesh, 0 for points.
    [[nodiscard]] std::size_t level_count() const;
};

/// \brief Reads `path`: a hierarchy (by its magic bytes), else a mesh if the file has faces,
/// else a point cloud. \throw IoError naming the file (the CLI's exit 3)
[[nodiscard]] ViewData read_view_data(const std::filesystem::path& path);

/// \brief "hierarchy", "mesh" or "points".
[[nodiscard]] const char* kind_name(ViewData::Kind kind);

/// \brief GET /api/info: the JSON description of the data (docs/viewer.md).
[[nodiscard]] std::string encode_info(const ViewData& data);

/// \brief GET /api/level/<i>: the 24-byte header, the float32 positions of the vertices new at
/// level i and the uint32 faces of level i (docs/viewer.md). \pre i < level count
[[nodiscard]] std::string encode_level(const ViewData& data, std::size_t level);

/// \brief GET /api/points: the 16-byte header, float32 positions, float32 normals if any,
/// uint8 RGB colours if any (docs/viewer.md). \pre data.kind == Points
[[nodiscard]] std::string encode_points(const ViewData& data);

/// \brief One of the page's files, held in memory.
struct StaticFile
{
    std::string content_type;
    std::string body;
};

/// \brief The page's files by URL path ("/", "/viewer.js", "/vendor/three.module.js", ...),
/// read from `viewer_dir` (viewer/ of the source tree: web/ and node_modules/three). Files that
/// are missing (three.js before `npm ci`) are left out and named in `missing`.
struct StaticFiles
{
    std::map<std::string, StaticFile> by_path;
    std::vector<std::string> missing;
};
[[nodiscard]] StaticFiles read_static_files(const std::filesystem::path& viewer_dir);

/// \brief Serves `data` and `files` on host:port (port 0: a free one) until stop_signal
/// is raised (SIGINT or SIGTERM). `on_listening` receives the port once the socket is bound,
/// before the first request is served.
/// \throw std::runtime_error if the address cannot be bound
void serve_view(const ViewData& data, const StaticFiles& files, const std::string& host, int port,
                const std::function<void(int)>& on_listening);

} // namespace pointform::cli
