// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "view_server.h"

#include "pointform/core/error.h"
#include "pointform/core/json_depth.h"
#include "pointform/hermite/surfels.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/polygonize/reconstruct.h"

#include <nlohmann/json.hpp>

#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

namespace pointform::cli {
namespace {

// Binary answers are little-endian whatever the host (docs/viewer.md).
void append_u32(std::string& out, std::uint32_t value)
{
    const std::array<char, 4> bytes = {
        static_cast<char>(value & 0xFFU), static_cast<char>((value >> 8) & 0xFFU),
        static_cast<char>((value >> 16) & 0xFFU), static_cast<char>((value >> 24) & 0xFFU)};
    out.append(bytes.data(), bytes.size());
}

void append_f32(std::string& out, float value)
{
    append_u32(out, std::bit_cast<std::uint32_t>(value));
}

void append_f64(std::string& out, double value)
{
    const auto bits = std::bit_cast<std::uint64_t>(value);
    append_u32(out, static_cast<std::uint32_t>(bits & 0xFFFFFFFFU));
    append_u32(out, static_cast<std::uint32_t>(bits >> 32));
}

std::uint32_t to_u32(std::size_t n)
{
    if (n > std::numeric_limits<std::uint32_t>::max())
        throw InvalidInput("more than 2^32 - 1 elements cannot be served");
    return static_cast<std::uint32_t>(n);
}

constexpr std::uint32_t binary_version = 1;

/// The bounding box of float positions relative to an origin, in those relative coordinates.
template <typename Positions>
nlohmann::json box_json(const Positions& positions)
{
    std::array<double, 3> lo = {0, 0, 0};
    std::array<double, 3> hi = {0, 0, 0};
    bool first = true;
    for (const auto& p : positions)
        for (int k = 0; k < 3; ++k)
        {
            const auto x = static_cast<double>(static_cast<float>(p[k]));
            lo[k] = first ? x : std::min(lo[k], x);
            hi[k] = first ? x : std::max(hi[k], x);
            first = first && k < 2;
        }
    return {{"min", lo}, {"max", hi}};
}

std::string read_whole_file(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        return {};
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// SIGINT and SIGTERM write a byte to this pipe (async-signal-safe); a thread reads it and stops
// the server, whichever thread the signal was delivered to.
std::array<int, 2> stop_pipe = {-1, -1};

extern "C" void on_stop_signal(int /*signal*/)
{
    const int saved = errno;
    const char byte = 1;
    [[maybe_unused]] const auto n = ::write(stop_pipe[1], &byte, 1);
    errno = saved;
}

/// Headers larger than this in all (names, values and separators) get 431.
constexpr std::size_t max_header_bytes = 16 * 1024;
/// POST /api/reconstruct: max_picked_triangles triangles of three indices of up to 10 digits.
constexpr std::size_t max_reconstruct_body_bytes = 4 * 1024 * 1024;

void set_error(httplib::Response& res, int status, const std::string& message)
{
    res.status = status;
    res.set_content(message + "\n", "text/plain; charset=utf-8");
}

} // namespace

std::size_t ViewData::level_count() const
{
    switch (kind)
    {
        case Kind::Hierarchy:
            return hierarchy->level_count();
        case Kind::Mesh:
            return 1;
        case Kind::Points:
            return 0;
    }
    return 0;
}

const char* kind_name(ViewData::Kind kind)
{
    switch (kind)
    {
        case ViewData::Kind::Hierarchy:
            return "hierarchy";
        case ViewData::Kind::Mesh:
            return "mesh";
        case ViewData::Kind::Points:
            return "points";
    }
    return "points";
}

ViewData read_view_data(const std::filesystem::path& path)
{
    ViewData data;
    data.name = path.filename().string();
    if (is_hierarchy_file(path) || path.extension() == ".pfh")
    {
        data.kind = ViewData::Kind::Hierarchy;
        data.hierarchy = read_hierarchy(path);
        return data;
    }
    ReadResult read = read_geometry(path);
    if (read.points.size() == 0)
        throw IoError(path, "no points to show");
    if (!read.triangles.empty())
    {
        data.kind = ViewData::Kind::Mesh;
        data.mesh.vertices = std::move(read.points);
        data.mesh.triangles = std::move(read.triangles);
        return data;
    }
    data.kind = ViewData::Kind::Points;
    data.points = std::move(read.points);
    return data;
}

TriMesh ViewData::level_mesh(std::size_t level) const
{
    PF_ASSERT(level < level_count());
    return kind == Kind::Mesh ? mesh : hierarchy->level_mesh(level);
}

nlohmann::json encode_info(const ViewData& data)
{
    nlohmann::json out;
    out["kind"] = kind_name(data.kind);
    out["file"] = data.name;
    nlohmann::json levels = nlohmann::json::array();
    Vec3d origin = Vec3d::Zero();
    if (data.kind == ViewData::Kind::Hierarchy)
    {
        const MultiresMesh& mesh = *data.hierarchy;
        origin = mesh.origin();
        for (std::size_t l = 0; l < mesh.level_count(); ++l)
        {
            const std::size_t first = l == 0 ? 0 : mesh.vertex_count(l - 1);
            levels.push_back({{"level", l},
                              {"vertices", mesh.vertex_count(l)},
                              {"new_vertices", mesh.vertex_count(l) - first},
                              {"faces", mesh.face_count(l)}});
        }
        out["bounding_box"] = box_json(mesh.positions());
        out["predictor"] = mesh.predictor() == Predictor::Butterfly ? "butterfly" : "midpoint";
    }
    else if (data.kind == ViewData::Kind::Mesh)
    {
        origin = data.mesh.vertices.origin;
        levels.push_back({{"level", 0},
                          {"vertices", data.mesh.vertex_count()},
                          {"new_vertices", data.mesh.vertex_count()},
                          {"faces", data.mesh.face_count()}});
        out["bounding_box"] = box_json(data.mesh.vertices.positions);
    }
    else
    {
        origin = data.points.origin;
        out["points"] = data.points.size();
        out["normals"] = data.points.has_normals();
        out["colors"] = data.points.has_colors();
        out["bounding_box"] = box_json(data.points.positions);
    }
    out["levels"] = levels;
    out["origin"] = {origin.x(), origin.y(), origin.z()};
    return out;
}

std::string encode_level(const ViewData& data, std::size_t level)
{
    PF_ASSERT(level < data.level_count());
    std::string out;
    const auto header = [&out](std::size_t lvl, std::size_t first, std::size_t count,
                               std::size_t faces) {
        out.append("PFLV", 4);
        append_u32(out, binary_version);
        append_u32(out, to_u32(lvl));
        append_u32(out, to_u32(first));
        append_u32(out, to_u32(count));
        append_u32(out, to_u32(faces));
    };
    const auto append_faces = [&out](const std::vector<Triangle>& faces) {
        for (const Triangle& t : faces)
            for (const std::uint32_t v : t)
                append_u32(out, v);
    };
    if (data.kind == ViewData::Kind::Mesh)
    {
        const TriMesh& mesh = data.mesh;
        out.reserve(24 + 12 * mesh.vertex_count() + 12 * mesh.face_count());
        header(0, 0, mesh.vertex_count(), mesh.face_count());
        for (const Vec3f& p : mesh.vertices.positions)
            for (int k = 0; k < 3; ++k)
                append_f32(out, p[k]);
        append_faces(mesh.triangles);
        return out;
    }
    const MultiresMesh& mesh = *data.hierarchy;
    const std::size_t first = level == 0 ? 0 : mesh.vertex_count(level - 1);
    const std::size_t end = mesh.vertex_count(level);
    const std::vector<Triangle> faces = mesh.faces(level);
    out.reserve(24 + 12 * (end - first) + 12 * faces.size());
    header(level, first, end - first, faces.size());
    // Rounded to float as MultiresMesh::level_mesh() rounds them: every level's vertices are
    // bit for bit the prefix of the next level's.
    const auto positions = mesh.positions();
    for (std::size_t v = first; v < end; ++v)
        for (int k = 0; k < 3; ++k)
            append_f32(out, static_cast<float>(positions[v][k]));
    append_faces(faces);
    return out;
}

std::string encode_points(const ViewData& data)
{
    PF_ASSERT(data.kind == ViewData::Kind::Points);
    const PointCloud& cloud = data.points;
    std::string out;
    out.reserve(16 + cloud.size() *
                         (12 + (cloud.has_normals() ? 12 : 0) + (cloud.has_colors() ? 3 : 0)));
    out.append("PFPT", 4);
    append_u32(out, binary_version);
    append_u32(out, to_u32(cloud.size()));
    append_u32(out, (cloud.has_normals() ? 1U : 0U) | (cloud.has_colors() ? 2U : 0U));
    for (const Vec3f& p : cloud.positions)
        for (int k = 0; k < 3; ++k)
            append_f32(out, p[k]);
    for (const Vec3f& n : cloud.normals)
        for (int k = 0; k < 3; ++k)
            append_f32(out, n[k]);
    for (const Color& c : cloud.colors)
    {
        out.push_back(static_cast<char>(c.r));
        out.push_back(static_cast<char>(c.g));
        out.push_back(static_cast<char>(c.b));
    }
    return out;
}

std::string encode_distances(const ViewData& data, std::size_t level, const PointCloud& samples)
{
    PF_ASSERT(level < data.level_count() && !samples.empty());
    const TriMesh mesh = data.level_mesh(level);
    // Vertices to samples (what the colours show) and samples to the level (the one-sided
    // Hausdorff distance of the refinement's report), both with the library's metrics.
    const std::vector<double> to_samples = distances_to_points(mesh.vertices, samples);
    const DistanceStats from_samples = summarize_distances(distances_to_mesh(samples, mesh));
    const double largest =
        to_samples.empty() ? 0.0 : *std::max_element(to_samples.begin(), to_samples.end());
    std::string out;
    out.reserve(40 + 4 * to_samples.size());
    out.append("PFDS", 4);
    append_u32(out, binary_version);
    append_u32(out, to_u32(level));
    append_u32(out, to_u32(to_samples.size()));
    append_f64(out, from_samples.max);
    append_f64(out, from_samples.mean);
    append_f64(out, largest);
    for (const double d : to_samples)
        append_f32(out, static_cast<float>(d));
    return out;
}

std::vector<Triangle> parse_picked_request(const std::string& body)
{
    // Depth first: the request is three levels deep, and a hostile body of a million '['
    // must not reach a recursive parser or destructor.
    if (json_nests_deeper_than(body, 4))
        throw InvalidInput("the request is nested deeper than {\"triangles\": [[i, j, k]]}");
    nlohmann::json request;
    try
    {
        request = nlohmann::json::parse(body);
    }
    catch (const nlohmann::json::parse_error& e)
    {
        throw InvalidInput(std::string("the request is not JSON: ") + e.what());
    }
    if (!request.is_object() || !request.contains("triangles") || !request["triangles"].is_array())
        throw InvalidInput("expected {\"triangles\": [[i, j, k], ...]} over sample indices");
    const nlohmann::json& triangles = request["triangles"];
    if (triangles.empty())
        throw InvalidInput("no triangles: join three picked samples first");
    if (triangles.size() > max_picked_triangles)
        throw InvalidInput(std::to_string(triangles.size()) + " triangles: at most " +
                           std::to_string(max_picked_triangles) + " may be picked");
    std::vector<Triangle> out;
    out.reserve(triangles.size());
    for (std::size_t f = 0; f < triangles.size(); ++f)
    {
        const nlohmann::json& t = triangles[f];
        const std::string which = "triangle " + std::to_string(f + 1);
        if (!t.is_array() || t.size() != 3)
            throw InvalidInput(which + " is not three sample indices");
        Triangle triangle{};
        for (std::size_t k = 0; k < 3; ++k)
        {
            // Whether it names a sample is picked_vertices_from_samples()'s to say.
            if (!t[k].is_number_unsigned() ||
                t[k].get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max())
                throw InvalidInput(which + ": " + t[k].dump() + " is not a sample index");
            triangle[k] = static_cast<std::uint32_t>(t[k].get<std::uint64_t>());
        }
        out.push_back(triangle);
    }
    return out;
}

StaticFiles read_static_files(const std::filesystem::path& viewer_dir)
{
    // The fixed list of names the server answers besides /api: URL path, file, content type.
    struct Entry
    {
        const char* url;
        const char* file;
        const char* type;
    };
    static constexpr std::array<Entry, 7> entries = {{
        {"/", "web/index.html", "text/html; charset=utf-8"},
        {"/viewer.js", "web/viewer.js", "text/javascript; charset=utf-8"},
        {"/base_mesh.js", "web/base_mesh.js", "text/javascript; charset=utf-8"},
        {"/style.css", "web/style.css", "text/css; charset=utf-8"},
        {"/vendor/three.module.js", "node_modules/three/build/three.module.js",
         "text/javascript; charset=utf-8"},
        {"/vendor/three.core.js", "node_modules/three/build/three.core.js",
         "text/javascript; charset=utf-8"},
        {"/vendor/OrbitControls.js", "node_modules/three/examples/jsm/controls/OrbitControls.js",
         "text/javascript; charset=utf-8"},
    }};
    StaticFiles files;
    for (const Entry& e : entries)
    {
        const std::filesystem::path path = viewer_dir / e.file;
        std::string body = read_whole_file(path);
        if (body.empty())
            files.missing.push_back(path.string());
        else
            files.by_path.emplace(e.url, StaticFile{e.type, std::move(body)});
    }
    return files;
}

namespace {

/// A layer as served: its data and its answers, encoded once; distances on first request.
struct Layer
{
    ViewData data;
    nlohmann::json info;
    std::vector<std::string> levels;
    std::string points;

    std::mutex distance_mutex;
    std::vector<std::string> distances; ///< per level, empty until asked for
};

std::shared_ptr<Layer> make_layer(ViewData data, std::size_t id, nlohmann::json extra = {})
{
    auto layer = std::make_shared<Layer>();
    layer->info = encode_info(data);
    layer->info["id"] = id;
    for (auto& [key, value] : extra.items())
        layer->info[key] = value;
    layer->levels.resize(data.level_count());
    for (std::size_t l = 0; l < layer->levels.size(); ++l)
        layer->levels[l] = encode_level(data, l);
    if (data.kind == ViewData::Kind::Points)
        layer->points = encode_points(data);
    layer->distances.resize(data.level_count());
    layer->data = std::move(data);
    return layer;
}

/// The reconstruction the page asked for: one at a time, on its own thread.
class ReconstructionJob
{
public:
    enum class State
    {
        Idle,
        Running,
        Done,
        Failed
    };

    /// Starts a job unless one is running; `work` gets the job's number (1, 2, ...).
    /// \return false if one is running
    bool start(std::function<void(ReconstructionJob&, long long)> work)
    {
        const std::lock_guard lock(mutex_);
        if (state_ == State::Running)
            return false;
        if (thread_.joinable())
            thread_.join();
        ++id_;
        state_ = State::Running;
        stage_ = "starting";
        fraction_ = 0.0;
        message_.clear();
        layer_ = -1;
        started_ = std::chrono::steady_clock::now();
        thread_ = std::thread([this, work = std::move(work), id = id_] { work(*this, id); });
        return true;
    }

    /// The progress callback of the library calls: records the stage, says stop on shutdown.
    bool progress(std::string_view stage, double fraction)
    {
        const std::lock_guard lock(mutex_);
        stage_ = std::string(stage);
        fraction_ = fraction;
        return !cancel_.load();
    }

    void finish(std::size_t layer, nlohmann::json report)
    {
        const std::lock_guard lock(mutex_);
        state_ = State::Done;
        layer_ = static_cast<long long>(layer);
        report_ = std::move(report);
        seconds_ = elapsed();
    }

    void fail(const std::string& message)
    {
        const std::lock_guard lock(mutex_);
        state_ = State::Failed;
        message_ = message;
        seconds_ = elapsed();
    }

    [[nodiscard]] nlohmann::json status()
    {
        const std::lock_guard lock(mutex_);
        static constexpr std::array<const char*, 4> names = {"idle", "running", "done", "failed"};
        nlohmann::json out = {{"state", names[static_cast<int>(state_)]}, {"job", id_}};
        if (state_ == State::Running)
        {
            out["stage"] = stage_;
            out["fraction"] = fraction_;
            out["seconds"] = elapsed();
        }
        if (state_ == State::Done)
        {
            out["layer"] = layer_;
            out["report"] = report_;
        }
        if (state_ == State::Failed)
            out["message"] = message_;
        if (state_ == State::Done || state_ == State::Failed)
            out["seconds"] = seconds_;
        return out;
    }

    /// Asks a running job to stop and waits for it.
    void stop()
    {
        cancel_ = true;
        std::thread thread;
        {
            const std::lock_guard lock(mutex_);
            thread = std::move(thread_);
        }
        if (thread.joinable())
            thread.join();
    }

    ~ReconstructionJob() { stop(); }

private:
    [[nodiscard]] double elapsed() const
    {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    }

    std::mutex mutex_;
    std::thread thread_;
    std::atomic<bool> cancel_{false};
    State state_ = State::Idle;
    long long id_ = 0;
    std::string stage_;
    double fraction_ = 0.0;
    std::string message_;
    long long layer_ = -1;
    nlohmann::json report_;
    double seconds_ = 0.0;
    std::chrono::steady_clock::time_point started_;
};

/// The refinement report's per-level figures, level 0 (the base mesh) included.
nlohmann::json level_report(const SemiRegularReport& report)
{
    const RefineReport& r = report.refinement;
    nlohmann::json levels = nlohmann::json::array();
    levels.push_back({{"level", 0},
                      {"hausdorff", r.initial_hausdorff},
                      {"mean_distance", r.initial_mean_distance}});
    for (const RefineLevelStats& s : r.levels)
    {
        nlohmann::json entry = {{"level", s.level}, {"unprojected", s.unprojected}};
        if (s.hausdorff)
            entry["hausdorff"] = *s.hausdorff;
        if (s.mean_distance)
            entry["mean_distance"] = *s.mean_distance;
        levels.push_back(entry);
    }
    return levels;
}

} // namespace

void serve_view(std::vector<ViewData> inputs, const StaticFiles& files, const std::string& host,
                int port, const std::function<void(int)>& on_listening)
{
    // Everything served is encoded here, before the socket is bound: requests only copy bytes.
    std::mutex layers_mutex;
    std::vector<std::shared_ptr<Layer>> layers;
    std::optional<std::size_t> samples_layer;
    for (ViewData& data : inputs)
    {
        if (data.kind == ViewData::Kind::Points && !samples_layer)
            samples_layer = layers.size();
        layers.push_back(make_layer(std::move(data), layers.size(), {{"source", "file"}}));
    }
    const auto layer_at = [&](std::size_t k) -> std::shared_ptr<Layer> {
        const std::lock_guard lock(layers_mutex);
        return k < layers.size() ? layers[k] : nullptr;
    };
    // The samples stay in their layer, which is never removed or changed.
    const PointCloud* samples = samples_layer ? &layers[*samples_layer]->data.points : nullptr;
    ReconstructionJob job;

    httplib::Server server;
    // SO_REUSEADDR (a restart may bind while old connections linger in TIME_WAIT) but not
    // cpp-httplib's default SO_REUSEPORT, with which a second server would share the port.
    server.set_socket_options([](socket_t sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    server.set_payload_max_length(max_reconstruct_body_bytes);
    server.set_read_timeout(5, 0);
    server.set_write_timeout(30, 0);
    server.set_keep_alive_max_count(100);

    // Before routing (and before a body is read): refuse oversized headers (cpp-httplib's own
    // limit is per line). Bodies beyond max_reconstruct_body_bytes get 413 from cpp-httplib; only
    // POST /api/reconstruct reads one.
    server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
        std::size_t header_bytes = req.target.size();
        for (const auto& [name, value] : req.headers)
            header_bytes += name.size() + value.size() + 4;
        if (header_bytes > max_header_bytes)
        {
            set_error(res, 431, "request headers too large");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });

    server.Get("/api/info", [&](const httplib::Request&, httplib::Response& res) {
        nlohmann::json info;
        info["layers"] = nlohmann::json::array();
        {
            const std::lock_guard lock(layers_mutex);
            for (const auto& layer : layers)
                info["layers"].push_back(layer->info);
        }
        info["samples"] = samples_layer ? nlohmann::json(*samples_layer) : nlohmann::json(nullptr);
        info["max_picked_triangles"] = max_picked_triangles;
        res.set_content(info.dump(), "application/json");
    });

    // /api/layer/<k>/<what>[/<i>]
    const auto layer_of = [&](const httplib::Request& req,
                              httplib::Response& res) -> std::shared_ptr<Layer> {
        const std::size_t k = std::stoul(req.matches[1].str());
        std::shared_ptr<Layer> layer = layer_at(k);
        if (!layer)
            set_error(res, 404, "layer " + std::to_string(k) + " does not exist");
        return layer;
    };
    const auto level_of = [](const Layer& layer, const httplib::Request& req,
                             httplib::Response& res) -> std::optional<std::size_t> {
        const std::size_t level = std::stoul(req.matches[2].str());
        if (level >= layer.levels.size())
        {
            set_error(res, 404,
                      "level " + std::to_string(level) + " does not exist: the layer has " +
                          std::to_string(layer.levels.size()) + " levels");
            return std::nullopt;
        }
        return level;
    };
    server.Get(R"(/api/layer/([0-9]{1,9})/level/([0-9]{1,9}))",
               [&](const httplib::Request& req, httplib::Response& res) {
                   const auto layer = layer_of(req, res);
                   if (!layer)
                       return;
                   if (const auto level = level_of(*layer, req, res))
                       res.set_content(layer->levels[*level], "application/octet-stream");
               });
    server.Get(R"(/api/layer/([0-9]{1,9})/distance/([0-9]{1,9}))", [&](const httplib::Request& req,
                                                                       httplib::Response& res) {
        const auto layer = layer_of(req, res);
        if (!layer)
            return;
        if (!samples)
        {
            set_error(res, 404, "no samples: name a point cloud on the command line too");
            return;
        }
        const auto level = level_of(*layer, req, res);
        if (!level)
            return;
        const std::lock_guard lock(layer->distance_mutex);
        std::string& answer = layer->distances[*level];
        if (answer.empty())
            answer = encode_distances(layer->data, *level, *samples);
        res.set_content(answer, "application/octet-stream");
    });
    server.Get(R"(/api/layer/([0-9]{1,9})/points)", [&](const httplib::Request& req,
                                                        httplib::Response& res) {
        const auto layer = layer_of(req, res);
        if (!layer)
            return;
        if (layer->points.empty())
        {
            set_error(res, 404,
                      std::string("no points: the layer is a ") + kind_name(layer->data.kind));
            return;
        }
        res.set_content(layer->points, "application/octet-stream");
    });
    server.Get(R"(/api/layer/(.*))", [](const httplib::Request& req, httplib::Response& res) {
        set_error(res, 400,
                  "bad layer request \"" + req.matches[1].str() +
                      "\": expected <k>/level/<i>, <k>/distance/<i> or <k>/points");
    });

    server.Get("/api/reconstruct", [&](const httplib::Request&, httplib::Response& res) {
        res.set_content(job.status().dump(), "application/json");
    });
    server.Post("/api/reconstruct", [&](const httplib::Request& req, httplib::Response& res) {
        if (!samples)
        {
            set_error(res, 404,
                      "no samples to reconstruct from: name a point cloud on the command line");
            return;
        }
        PickedVertices vertices;
        try
        {
            vertices = picked_vertices_from_samples(parse_picked_request(req.body), *samples,
                                                    "the picked base mesh");
        }
        catch (const InvalidInput& e)
        {
            set_error(res, 400, e.what());
            return;
        }
        const bool started = job.start([&, vertices = std::move(vertices)](
                                           ReconstructionJob& self, long long number) mutable {
            try
            {
                const ProgressCallback progress = [&self](std::string_view stage, double f) {
                    return self.progress(stage, f);
                };
                // What `pointform reconstruct SCAN --base-mesh PICKED.obj` runs, at its defaults.
                SurfelsFromSamples surfels = surfels_from_samples(*samples, {.progress = progress});
                ReconstructOptions options;
                options.picked_vertices = std::move(vertices);
                options.progress = progress;
                ReconstructReport report = reconstruct(std::move(surfels.surfels), options);
                nlohmann::json summary = {
                    {"levels", level_report(report.semi_regular)},
                    {"stop", std::string(to_string(report.semi_regular.refinement.stop))},
                    {"base_faces", report.picked->mesh.face_count()},
                    {"reoriented_faces", report.picked->reoriented_faces},
                    {"euler_characteristic", report.picked->topology.euler_characteristic},
                    {"boundary_loops", report.picked->topology.boundary_loops}};
                ViewData data;
                data.kind = ViewData::Kind::Hierarchy;
                data.name = "reconstruction " + std::to_string(number);
                data.hierarchy = std::move(report.semi_regular.hierarchy);
                std::size_t id = 0;
                {
                    const std::lock_guard lock(layers_mutex);
                    id = layers.size();
                    auto layer = make_layer(std::move(data), id,
                                            {{"source", "reconstruction"}, {"report", summary}});
                    layers.push_back(std::move(layer));
                }
                self.finish(id, std::move(summary));
            }
            catch (const Cancelled&)
            {
                self.fail("cancelled");
            }
            catch (const std::bad_alloc&)
            {
                self.fail("out of memory");
            }
            catch (const std::exception& e)
            {
                self.fail(e.what());
            }
        });
        if (!started)
        {
            set_error(res, 409, "a reconstruction is already running");
            return;
        }
        res.status = 202;
        res.set_content(job.status().dump(), "application/json");
    });

    server.Get(R"(/.*)", [&files](const httplib::Request& req, httplib::Response& res) {
        const auto it = files.by_path.find(req.path);
        if (it == files.by_path.end())
        {
            set_error(res, 404, "not found");
            return;
        }
        res.set_content(it->second.body, it->second.content_type.c_str());
        res.set_header("Cache-Control", "no-cache");
    });
    const auto not_allowed = [](const httplib::Request& req, httplib::Response& res) {
        const bool reconstruct = req.path == "/api/reconstruct";
        res.set_header("Allow", reconstruct ? "GET, HEAD, POST" : "GET, HEAD");
        set_error(res, 405,
                  reconstruct ? "GET or POST /api/reconstruct"
                              : "only GET is served here (POST only to /api/reconstruct)");
    };
    server.Post(R"(/.*)", not_allowed);
    server.Put(R"(/.*)", not_allowed);
    server.Patch(R"(/.*)", not_allowed);
    server.Delete(R"(/.*)", not_allowed);
    server.Options(R"(/.*)", not_allowed);
    server.set_default_headers({{"X-Content-Type-Options", "nosniff"}});

    int bound = port;
    if (port == 0)
        bound = server.bind_to_any_port(host);
    else if (!server.bind_to_port(host, port))
        bound = -1;
    if (bound < 0)
        throw std::runtime_error("cannot listen on " + host + ":" + std::to_string(port) + ": " +
                                 std::strerror(errno));

    if (::pipe(stop_pipe.data()) != 0)
        throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
    struct sigaction action = {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    struct sigaction old_int = {};
    struct sigaction old_term = {};
    ::sigaction(SIGINT, &action, &old_int);
    ::sigaction(SIGTERM, &action, &old_term);
    std::thread stopper([&server] {
        char byte = 0;
        while (::read(stop_pipe[0], &byte, 1) < 0 && errno == EINTR)
        {}
        server.stop();
    });

    on_listening(bound);
    server.listen_after_bind();

    // listen_after_bind() also returns when the socket fails; make the stopper finish either way.
    on_stop_signal(0);
    stopper.join();
    job.stop(); // a running reconstruction is cancelled at its next progress report
    ::sigaction(SIGINT, &old_int, nullptr);
    ::sigaction(SIGTERM, &old_term, nullptr);
    ::close(stop_pipe[0]);
    ::close(stop_pipe[1]);
    stop_pipe = {-1, -1};
}

} // namespace pointform::cli
