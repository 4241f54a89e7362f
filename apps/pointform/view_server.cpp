// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "view_server.h"

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include <nlohmann/json.hpp>

#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
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
/// GET requests have no body; anything larger than this is refused with 413.
constexpr std::size_t max_payload_bytes = 1024;

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

std::string encode_info(const ViewData& data)
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
    return out.dump();
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

StaticFiles read_static_files(const std::filesystem::path& viewer_dir)
{
    // The fixed list of names the server answers besides /api: URL path, file, content type.
    struct Entry
    {
        const char* url;
        const char* file;
        const char* type;
    };
    static constexpr std::array<Entry, 6> entries = {{
        {"/", "web/index.html", "text/html; charset=utf-8"},
        {"/viewer.js", "web/viewer.js", "text/javascript; charset=utf-8"},
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

void serve_view(const ViewData& data, const StaticFiles& files, const std::string& host, int port,
                const std::function<void(int)>& on_listening)
{
    // Everything served is encoded here, before the socket is bound: requests only copy bytes.
    const std::string info = encode_info(data);
    std::vector<std::string> levels(data.level_count());
    for (std::size_t l = 0; l < levels.size(); ++l)
        levels[l] = encode_level(data, l);
    const std::string points =
        data.kind == ViewData::Kind::Points ? encode_points(data) : std::string();

    httplib::Server server;
    // SO_REUSEADDR (a restart may bind while old connections linger in TIME_WAIT) but not
    // cpp-httplib's default SO_REUSEPORT, with which a second server would share the port.
    server.set_socket_options([](socket_t sock) {
        int yes = 1;
        ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    server.set_payload_max_length(max_payload_bytes);
    server.set_read_timeout(5, 0);
    server.set_write_timeout(30, 0);
    server.set_keep_alive_max_count(100);

    // Before routing: refuse oversized headers (cpp-httplib's own limit is per line) and
    // bodies (the GET endpoints take none).
    server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
        std::size_t header_bytes = req.target.size();
        for (const auto& [name, value] : req.headers)
            header_bytes += name.size() + value.size() + 4;
        if (header_bytes > max_header_bytes)
        {
            set_error(res, 431, "request headers too large");
            return httplib::Server::HandlerResponse::Handled;
        }
        if (req.body.size() > max_payload_bytes)
        {
            set_error(res, 413, "request body too large");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });

    server.Get("/api/info", [&info](const httplib::Request&, httplib::Response& res) {
        res.set_content(info, "application/json");
    });
    server.Get(R"(/api/level/([0-9]{1,9}))", [&levels](const httplib::Request& req,
                                                       httplib::Response& res) {
        const std::size_t level = std::stoul(req.matches[1].str());
        if (level >= levels.size())
        {
            set_error(res, 404,
                      "level " + std::to_string(level) +
                          " does not exist: " + std::to_string(levels.size()) + " levels");
            return;
        }
        res.set_content(levels[level], "application/octet-stream");
    });
    server.Get(R"(/api/level/(.*))", [](const httplib::Request& req, httplib::Response& res) {
        set_error(res, 400, "bad level \"" + req.matches[1].str() + "\": expected 0, 1, 2, ...");
    });
    server.Get("/api/points", [&points, &data](const httplib::Request&, httplib::Response& res) {
        if (points.empty())
        {
            set_error(res, 404, std::string("no points: the file is a ") + kind_name(data.kind));
            return;
        }
        res.set_content(points, "application/octet-stream");
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
    const auto not_allowed = [](const httplib::Request&, httplib::Response& res) {
        res.set_header("Allow", "GET, HEAD");
        set_error(res, 405, "only GET is served");
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
    ::sigaction(SIGINT, &old_int, nullptr);
    ::sigaction(SIGTERM, &old_term, nullptr);
    ::close(stop_pipe[0]);
    ::close(stop_pipe[1]);
    stop_pipe = {-1, -1};
}

} // namespace pointform::cli
