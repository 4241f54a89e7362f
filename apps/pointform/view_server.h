// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief What `pointform view` serves: the layers (the files named on its command line, then
/// the reconstructions made from the page), each encoded once for the data endpoints
/// (docs/viewer.md), and the HTTP server (cpp-httplib) that answers a fixed list of names. No
/// path from a request ever reaches the file system: the page's files are read into memory
/// before serving.

#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pointform::cli {

/// \brief One thing a viewer shows: a file read before the server starts, or a reconstruction.
struct ViewData
{
    enum class Kind
    {
        Hierarchy, ///< a .pfh file or a reconstruction: every level
        Mesh,      ///< a triangle mesh: one level, drawn shaded
        Points     ///< a point cloud (or surfels): drawn as points, picked on
    };
    Kind kind = Kind::Points;
    std::string name;                      ///< the file's name (no directories)
    std::optional<MultiresMesh> hierarchy; ///< Hierarchy: its levels
    TriMesh mesh;                          ///< Mesh: the mesh, served as the only level 0
    PointCloud points;                     ///< Points: the points

    /// \brief Levels served by /api/layer/<k>/level: the hierarchy's, 1 for a mesh, 0 for points.
    [[nodiscard]] std::size_t level_count() const;
    /// \brief Level `level` as a mesh (a hierarchy's level or the mesh). \pre level < level_count()
    [[nodiscard]] TriMesh level_mesh(std::size_t level) const;
};

/// \brief Reads `path`: a hierarchy (by its magic bytes), else a mesh if the file has faces,
/// else a point cloud. \throw IoError naming the file (the CLI's exit 3)
[[nodiscard]] ViewData read_view_data(const std::filesystem::path& path);

/// \brief "hierarchy", "mesh" or "points".
[[nodiscard]] const char* kind_name(ViewData::Kind kind);

/// \brief One layer's entry of GET /api/info (docs/viewer.md): kind, file, levels, bounding
/// box, origin and what the points carry.
[[nodiscard]] nlohmann::json encode_info(const ViewData& data);

/// \brief GET /api/layer/<k>/level/<i>: the 24-byte header, the float32 positions of the
/// vertices new at level i and the uint32 faces of level i (docs/viewer.md).
/// \pre i < level count
[[nodiscard]] std::string encode_level(const ViewData& data, std::size_t level);

/// \brief GET /api/layer/<k>/points: the 16-byte header, float32 positions, float32 normals if
/// any, uint8 RGB colours if any (docs/viewer.md). \pre data.kind == Points
[[nodiscard]] std::string encode_points(const ViewData& data);

/// \brief GET /api/layer/<k>/distance/<i>: the 40-byte header (the one-sided Hausdorff distance
/// and the mean distance from the samples to level i, the largest vertex distance), then the
/// float32 distance from every vertex of level i to its nearest sample (docs/viewer.md).
/// \pre i < level count, samples not empty
[[nodiscard]] std::string encode_distances(const ViewData& data, std::size_t level,
                                           const PointCloud& samples);

/// \brief The base mesh a page sends with POST /api/reconstruct: {"triangles": [[i, j, k],
/// ...]} over the indices of the samples (the first point cloud's points), at most
/// max_picked_triangles. \return the triangles over sample indices, not yet checked against
/// the samples (picked_vertices_from_samples() does that)
/// \throw InvalidInput saying what is wrong with the request (the server's 400)
inline constexpr std::size_t max_picked_triangles = 100000;
[[nodiscard]] std::vector<Triangle> parse_picked_request(const std::string& body);

/// \brief One of the page's files, held in memory.
struct StaticFile
{
    std::string content_type;
    std::string body;
};

/// \brief The page's files by URL path ("/", "/viewer.js", "/vendor/three.module.js", ...),
/// read from `viewer_dir` (web/ and node_modules/three: viewer/ of the source tree, or the
/// installed share/pointform/viewer). Files that are missing (three.js before `npm ci`) are left
/// out and named in `missing`.
struct StaticFiles
{
    std::map<std::string, StaticFile> by_path;
    std::vector<std::string> missing;
};
[[nodiscard]] StaticFiles read_static_files(const std::filesystem::path& viewer_dir);

/// \brief Serves `layers` (the command line's files, in order) and `files` on host:port
/// (port 0: a free one) until SIGINT or SIGTERM. Reconstructions asked for by the page run on
/// the first point cloud among `layers` (surfels_from_samples() and reconstruct() with the
/// picked base mesh, as `pointform reconstruct --base-mesh` runs them) and are served as new
/// layers. `on_listening` receives the port once the socket is bound, before the first request
/// is served.
/// \throw std::runtime_error if the address cannot be bound
void serve_view(std::vector<ViewData> layers, const StaticFiles& files, const std::string& host,
                int port, const std::function<void(int)>& on_listening);

} // namespace pointform::cli
