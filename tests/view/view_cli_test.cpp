// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform view` as a child process, asked over HTTP with cpp-httplib's client: the page, the
// JSON description and the binary levels and points of the file named on the command line (byte
// sizes, headers, every face and position), 4xx answers to everything else (paths outside the
// fixed list, bad levels, other methods, oversized headers and bodies) after which the server
// still answers, exit 3 before serving a file that cannot be read, exit 0 on SIGINT and SIGTERM.

#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include "support/test_meshes.h"
#include "support/test_support.h"
#include "support/textured_fixtures.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <httplib.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

namespace pointform {
namespace {

/// `pointform view ARGS... --port 0` running as a child; stdout and stderr go to a pipe that is
/// read until the URL appears (or the child exits).
class ViewProcess
{
public:
    explicit ViewProcess(std::vector<std::string> args)
    {
        std::array<int, 2> fds = {-1, -1};
        if (::pipe(fds.data()) != 0)
            throw std::runtime_error("pipe failed");
        args.insert(args.begin(), {PF_CLI_PATH, "view"});
        pid_ = ::fork();
        if (pid_ == 0)
        {
            ::dup2(fds[1], STDOUT_FILENO);
            ::dup2(fds[1], STDERR_FILENO);
            ::close(fds[0]);
            ::close(fds[1]);
            std::vector<char*> argv;
            for (std::string& a : args)
                argv.push_back(a.data());
            argv.push_back(nullptr);
            ::execv(PF_CLI_PATH, argv.data());
            ::_exit(127);
        }
        ::close(fds[1]);
        out_fd_ = fds[0];
        // Read until the URL line is complete, the child closes its output, or 30 s pass.
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
        while (std::chrono::steady_clock::now() < deadline)
        {
            const std::size_t at = output_.find("http://");
            if (at != std::string::npos && output_.find('\n', at) != std::string::npos)
            {
                url_ = output_.substr(at, output_.find('\n', at) - at);
                const std::size_t colon = url_.rfind(':');
                port_ = std::stoi(url_.substr(colon + 1));
                return;
            }
            if (!read_some(1000))
                return;
        }
    }
    ~ViewProcess()
    {
        if (pid_ > 0 && !exited_)
        {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        if (out_fd_ >= 0)
            ::close(out_fd_);
    }
    ViewProcess(const ViewProcess&) = delete;
    ViewProcess& operator=(const ViewProcess&) = delete;

    [[nodiscard]] const std::string& url() const { return url_; }
    [[nodiscard]] int port() const { return port_; }
    [[nodiscard]] const std::string& output() const { return output_; }

    /// Sends `signal` (0: none) and waits for the exit code: -1 if killed by a signal or still
    /// running after 30 s (then killed).
    int stop(int signal)
    {
        if (signal != 0)
            ::kill(pid_, signal);
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
        while (std::chrono::steady_clock::now() < deadline && read_some(1000))
        {}
        int status = 0;
        while (::waitpid(pid_, &status, WNOHANG) == 0)
        {
            if (std::chrono::steady_clock::now() > deadline)
            {
                ::kill(pid_, SIGKILL);
                ::waitpid(pid_, &status, 0);
                exited_ = true;
                return -1;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        exited_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    [[nodiscard]] httplib::Client client() const
    {
        httplib::Client c("127.0.0.1", port_);
        c.set_connection_timeout(5, 0);
        c.set_read_timeout(10, 0);
        return c;
    }

private:
    /// Reads what is available within `ms`; false at end of output.
    bool read_some(int ms)
    {
        pollfd p = {out_fd_, POLLIN, 0};
        if (::poll(&p, 1, ms) <= 0)
            return true;
        std::array<char, 4096> buffer{};
        const ssize_t n = ::read(out_fd_, buffer.data(), buffer.size());
        if (n <= 0)
            return false;
        output_.append(buffer.data(), static_cast<std::size_t>(n));
        return true;
    }

    pid_t pid_ = -1;
    int out_fd_ = -1;
    bool exited_ = false;
    std::string output_;
    std::string url_;
    int port_ = 0;
};

std::uint32_t u32_at(const std::string& body, std::size_t offset)
{
    std::uint32_t v = 0;
    for (int k = 3; k >= 0; --k)
        v = (v << 8) | static_cast<unsigned char>(body[offset + static_cast<std::size_t>(k)]);
    return v;
}

float f32_at(const std::string& body, std::size_t offset)
{
    const std::uint32_t bits = u32_at(body, offset);
    float f = 0;
    std::memcpy(&f, &bits, sizeof f);
    return f;
}

int status_of(const httplib::Result& result)
{
    return result ? result->status : -1;
}

TEST(ViewCli, ServesTheHierarchyLevelByLevel)
{
    test::TempDir dir;
    const MultiresMesh mesh = test::plate_hierarchy(3); // far origin, boundary
    write_hierarchy(dir / "plate.pfh", mesh);
    ViewProcess server({(dir / "plate.pfh").string(), "--port", "0"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");
    auto client = server.client();

    const auto page = client.Get("/");
    ASSERT_EQ(status_of(page), 200);
    EXPECT_NE(page->body.find("importmap"), std::string::npos);
    EXPECT_NE(page->get_header_value("Content-Type").find("text/html"), std::string::npos);
    EXPECT_EQ(status_of(client.Get("/viewer.js")), 200);
    EXPECT_EQ(status_of(client.Get("/style.css")), 200);

    const auto info_answer = client.Get("/api/info");
    ASSERT_EQ(status_of(info_answer), 200);
    const auto all = nlohmann::json::parse(info_answer->body);
    ASSERT_EQ(all["layers"].size(), 1U);
    EXPECT_TRUE(all["samples"].is_null());
    const nlohmann::json& info = all["layers"][0];
    EXPECT_EQ(info["id"], 0);
    EXPECT_EQ(info["source"], "file");
    EXPECT_EQ(info["kind"], "hierarchy");
    EXPECT_EQ(info["file"], "plate.pfh");
    EXPECT_DOUBLE_EQ(info["origin"][0].get<double>(), mesh.origin().x());
    ASSERT_EQ(info["levels"].size(), mesh.level_count());
    for (std::size_t l = 0; l < mesh.level_count(); ++l)
    {
        EXPECT_EQ(info["levels"][l]["faces"], mesh.face_count(l));
        EXPECT_EQ(info["levels"][l]["vertices"], mesh.vertex_count(l));
    }

    for (std::size_t l = 0; l < mesh.level_count(); ++l)
    {
        SCOPED_TRACE("level " + std::to_string(l));
        const auto answer = client.Get("/api/layer/0/level/" + std::to_string(l));
        ASSERT_EQ(status_of(answer), 200);
        const std::string& body = answer->body;
        const std::size_t first = l == 0 ? 0 : mesh.vertex_count(l - 1);
        const std::size_t added = mesh.vertex_count(l) - first;
        const std::vector<Triangle> faces = mesh.faces(l);
        ASSERT_EQ(body.size(), 24 + 12 * added + 12 * faces.size());
        EXPECT_EQ(body.substr(0, 4), "PFLV");
        EXPECT_EQ(u32_at(body, 4), 1U);
        EXPECT_EQ(u32_at(body, 8), l);
        EXPECT_EQ(u32_at(body, 12), first);
        EXPECT_EQ(u32_at(body, 16), added);
        EXPECT_EQ(u32_at(body, 20), faces.size());
        const auto positions = mesh.positions();
        for (std::size_t v = 0; v < added; ++v)
            for (std::size_t k = 0; k < 3; ++k)
                ASSERT_EQ(f32_at(body, 24 + 12 * v + 4 * k),
                          static_cast<float>(positions[first + v][static_cast<int>(k)]));
        const std::size_t face_offset = 24 + 12 * added;
        for (std::size_t f = 0; f < faces.size(); ++f)
            for (std::size_t k = 0; k < 3; ++k)
                ASSERT_EQ(u32_at(body, face_offset + 12 * f + 4 * k), faces[f][k]);
    }
    EXPECT_EQ(status_of(client.Get("/api/layer/0/points")), 404);     // a hierarchy has no points
    EXPECT_EQ(status_of(client.Get("/api/layer/0/distance/0")), 404); // nor samples to measure
    EXPECT_EQ(status_of(client.Post("/api/reconstruct", "{\"triangles\": [[0, 1, 2]]}",
                                    "application/json")),
              404); // nor samples to pick on

    EXPECT_EQ(server.stop(SIGINT), 0) << server.output();
}

TEST(ViewCli, RefusesWhatItDoesNotServeAndKeepsServing)
{
    test::TempDir dir;
    write_hierarchy(dir / "sphere.pfh", test::sphere_hierarchy(2));
    ViewProcess server({(dir / "sphere.pfh").string(), "--port", "0"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    auto client = server.client();
    const auto still_serving = [&] {
        const auto info = client.Get("/api/info");
        return info && info->status == 200 && info->body.find("\"hierarchy\"") != std::string::npos;
    };

    for (const char* path : {"/../../etc/passwd",
                             "/etc/passwd",
                             "/sphere.pfh",
                             "/index.html",
                             "/web/index.html",
                             "/viewer/web/index.html",
                             "/vendor/../../CMakeLists.txt",
                             "/%2e%2e/%2e%2e/etc/passwd",
                             "/node_modules/three/package.json",
                             "/vendor/three.js",
                             "/api",
                             "/api/level/0",
                             "/api/layer",
                             "/api/layer/0",
                             "/api/layer/0/level",
                             "/api/layer/0/level/3",
                             "/api/layer/0/level/99",
                             "/api/layer/0/level/4294967296000",
                             "/api/layer/0/level/ 1",
                             "/api/layer/1/level/0",
                             "/api/layer/99999999999/points",
                             "/api/layer/0/other/1"})
    {
        SCOPED_TRACE(path);
        const int status = status_of(client.Get(path));
        EXPECT_GE(status, 400);
        EXPECT_LT(status, 500);
        EXPECT_TRUE(still_serving());
    }
    EXPECT_EQ(status_of(client.Get("/api/layer/0/level/-1")), 400);
    EXPECT_EQ(status_of(client.Get("/api/layer/0/level/one")), 400);
    EXPECT_EQ(status_of(client.Get("/api/layer/0/level/99")), 404);
    EXPECT_EQ(status_of(client.Get("/api/layer/3/level/0")), 404);

    // Methods other than GET (and HEAD).
    EXPECT_EQ(status_of(client.Post("/api/info", "x", "text/plain")), 405);
    EXPECT_EQ(status_of(client.Put("/", "x", "text/plain")), 405);
    EXPECT_EQ(status_of(client.Delete("/api/layer/0/level/0")), 405);
    EXPECT_EQ(status_of(client.Put("/api/reconstruct", "x", "text/plain")), 405);
    EXPECT_EQ(status_of(client.Head("/api/info")), 200);
    EXPECT_TRUE(still_serving());

    // Oversized requests: one huge header line, many headers, a large body.
    const int one_huge = status_of(client.Get("/", {{"X-Big", std::string(64 * 1024, 'a')}}));
    EXPECT_GE(one_huge, 400);
    EXPECT_LT(one_huge, 500);
    EXPECT_TRUE(still_serving());
    httplib::Headers many;
    for (int i = 0; i < 40; ++i)
        many.emplace("X-Filler-" + std::to_string(i), std::string(1000, 'b'));
    EXPECT_EQ(status_of(client.Get("/api/info", many)), 431);
    EXPECT_TRUE(still_serving());
    EXPECT_EQ(status_of(client.Get("/" + std::string(10000, 'a'))), 414);
    EXPECT_TRUE(still_serving());
    const int big_body =
        status_of(client.Post("/api/info", std::string(1 << 20, 'c'), "text/plain"));
    EXPECT_EQ(big_body, 405); // read (up to the 4 MiB limit of a picked base mesh), then refused
    EXPECT_TRUE(still_serving());
    const int huge_picked =
        status_of(client.Post("/api/reconstruct", std::string(5 << 20, '['), "application/json"));
    EXPECT_EQ(huge_picked, 413);
    EXPECT_TRUE(still_serving());

    EXPECT_EQ(server.stop(SIGTERM), 0) << server.output();
}

TEST(ViewCli, ServesAPointCloudAndAMesh)
{
    test::TempDir dir;
    PointCloud cloud;
    cloud.origin = Vec3d(10.0, 20.0, 30.0);
    for (int i = 0; i < 50; ++i)
    {
        const auto t = static_cast<float>(i);
        cloud.positions.emplace_back(0.01F * t, 0.5F - 0.02F * t, 0.25F);
        cloud.colors.push_back({static_cast<std::uint8_t>(5 * i), 100, 200});
    }
    write_point_cloud(dir / "cloud.ply", cloud);
    {
        ViewProcess server({(dir / "cloud.ply").string(), "--port", "0"});
        ASSERT_FALSE(server.url().empty()) << server.output();
        auto client = server.client();
        const auto all = nlohmann::json::parse(client.Get("/api/info")->body);
        EXPECT_EQ(all["samples"], 0);
        const nlohmann::json& info = all["layers"][0];
        EXPECT_EQ(info["kind"], "points");
        EXPECT_EQ(info["points"], 50);
        EXPECT_EQ(info["colors"], true);
        EXPECT_EQ(info["levels"].size(), 0U);
        const auto points = client.Get("/api/layer/0/points");
        ASSERT_EQ(status_of(points), 200);
        ASSERT_EQ(points->body.size(), 16U + 50U * 12U + 50U * 3U);
        EXPECT_EQ(points->body.substr(0, 4), "PFPT");
        EXPECT_EQ(u32_at(points->body, 8), 50U);
        EXPECT_EQ(u32_at(points->body, 12), 2U); // colours, no normals
        const ReadResult read = read_geometry(dir / "cloud.ply");
        for (std::size_t i = 0; i < 50; ++i)
        {
            EXPECT_EQ(f32_at(points->body, 16 + 12 * i + 4), read.points.positions[i].y());
            EXPECT_EQ(static_cast<unsigned char>(points->body[16 + 600 + 3 * i]), 5 * i);
        }
        EXPECT_EQ(status_of(client.Get("/api/layer/0/level/0")), 404);
        EXPECT_EQ(server.stop(SIGINT), 0);
    }

    const TriMesh sphere = test::icosphere(2);
    write_mesh(dir / "sphere.off", sphere);
    ViewProcess server({(dir / "sphere.off").string(), "--port", "0"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    auto client = server.client();
    const auto all = nlohmann::json::parse(client.Get("/api/info")->body);
    const nlohmann::json& info = all["layers"][0];
    EXPECT_EQ(info["kind"], "mesh");
    ASSERT_EQ(info["levels"].size(), 1U);
    EXPECT_EQ(info["levels"][0]["faces"], sphere.face_count());
    const auto level = client.Get("/api/layer/0/level/0");
    ASSERT_EQ(status_of(level), 200);
    EXPECT_EQ(level->body.size(), 24 + 12 * sphere.vertex_count() + 12 * sphere.face_count());
    EXPECT_EQ(status_of(client.Get("/api/layer/0/level/1")), 404);
    EXPECT_EQ(server.stop(SIGINT), 0);
}

/// `count` samples of the unit sphere around `centre` with their normals (a Fibonacci spiral).
PointCloud sphere_samples(std::size_t count, const Vec3d& centre)
{
    PointCloud cloud;
    cloud.origin = centre;
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (std::size_t i = 0; i < count; ++i)
    {
        const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(count);
        const double r = std::sqrt(1.0 - z * z);
        const double a = golden * static_cast<double>(i);
        const Vec3f p(static_cast<float>(r * std::cos(a)), static_cast<float>(r * std::sin(a)),
                      static_cast<float>(z));
        cloud.positions.push_back(p);
        cloud.normals.push_back(p.normalized());
    }
    return cloud;
}

/// The sample nearest to each of +x, -x, +y, -y, +z, -z and the octahedron over them.
std::string octahedron_request(const PointCloud& cloud)
{
    const std::array<Vec3f, 6> axes = {Vec3f::UnitX(), Vec3f(-Vec3f::UnitX()),
                                       Vec3f::UnitY(), Vec3f(-Vec3f::UnitY()),
                                       Vec3f::UnitZ(), Vec3f(-Vec3f::UnitZ())};
    std::array<std::size_t, 6> nearest{};
    for (std::size_t a = 0; a < 6; ++a)
        for (std::size_t i = 0; i < cloud.size(); ++i)
            if ((cloud.positions[i] - axes[a]).norm() <
                (cloud.positions[nearest[a]] - axes[a]).norm())
                nearest[a] = i;
    constexpr std::array<std::array<int, 3>, 8> faces = {
        {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}}};
    nlohmann::json triangles = nlohmann::json::array();
    for (const auto& f : faces)
        triangles.push_back({nearest[f[0]], nearest[f[2]], nearest[f[1]]}); // inwards: turned
    return nlohmann::json{{"triangles", triangles}}.dump();
}

/// Polls GET /api/reconstruct until the job is no longer running (at most a minute).
nlohmann::json wait_for_job(httplib::Client& client)
{
    nlohmann::json status;
    for (int i = 0; i < 600; ++i)
    {
        const auto answer = client.Get("/api/reconstruct");
        if (!answer)
            return {};
        status = nlohmann::json::parse(answer->body);
        if (status["state"] != "running")
            break;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return status;
}

TEST(ViewCli, ReconstructsAPickedBaseMeshAndServesItsLevels)
{
    test::TempDir dir;
    const PointCloud cloud = sphere_samples(3000, Vec3d(100.0, -50.0, 20.0));
    write_point_cloud(dir / "sphere.ply", cloud);
    ViewProcess server({(dir / "sphere.ply").string(), "--port", "0", "-j", "2"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    auto client = server.client();
    EXPECT_EQ(nlohmann::json::parse(client.Get("/api/reconstruct")->body)["state"], "idle");

    // Malformed requests: 400 with the reason, nothing started.
    for (const std::string& body : std::vector<std::string>{
             "", "x", "[]", "{}", "{\"triangles\": 3}", "{\"triangles\": []}",
             "{\"triangles\": [[0, 1]]}", "{\"triangles\": [[0, 1, 3000]]}",
             "{\"triangles\": [[0, 1, -1]]}", "{\"triangles\": [[0, 1, 2.5]]}",
             "{\"triangles\": [[0, 1, \"2\"]]}",
             std::string(100000, '[') + std::string(100000, ']'), "{\"triangles\": [[[[0]]]]}"})
    {
        SCOPED_TRACE(body.substr(0, 40));
        const auto answer = client.Post("/api/reconstruct", body, "application/json");
        ASSERT_TRUE(answer);
        EXPECT_EQ(answer->status, 400) << answer->body;
    }
    EXPECT_EQ(nlohmann::json::parse(client.Get("/api/reconstruct")->body)["state"], "idle");

    // The octahedron: accepted, reconstructed, served as layer 1.
    const auto started =
        client.Post("/api/reconstruct", octahedron_request(cloud), "application/json");
    ASSERT_TRUE(started);
    EXPECT_EQ(started->status, 202) << started->body;
    const nlohmann::json done = wait_for_job(client);
    ASSERT_EQ(done["state"], "done") << done.dump();
    EXPECT_EQ(done["layer"], 1);
    EXPECT_EQ(done["report"]["base_faces"], 8);
    EXPECT_EQ(done["report"]["reoriented_faces"], 8);
    EXPECT_EQ(done["report"]["euler_characteristic"], 2);
    const auto all = nlohmann::json::parse(client.Get("/api/info")->body);
    ASSERT_EQ(all["layers"].size(), 2U);
    const nlohmann::json& layer = all["layers"][1];
    EXPECT_EQ(layer["kind"], "hierarchy");
    EXPECT_EQ(layer["source"], "reconstruction");
    const std::size_t levels = layer["levels"].size();
    ASSERT_GE(levels, 3U);
    ASSERT_EQ(layer["report"]["levels"].size(), levels);
    for (std::size_t l = 0; l < levels; ++l)
    {
        SCOPED_TRACE("level " + std::to_string(l));
        EXPECT_EQ(layer["levels"][l]["faces"], 8U << (2 * l));
        const auto answer = client.Get("/api/layer/1/level/" + std::to_string(l));
        ASSERT_EQ(status_of(answer), 200);
        EXPECT_EQ(u32_at(answer->body, 20), 8U << (2 * l));
        // Every vertex on the unit sphere (relative to the hierarchy's origin).
        const Vec3d origin(layer["origin"][0].get<double>(), layer["origin"][1].get<double>(),
                           layer["origin"][2].get<double>());
        const std::uint32_t added = u32_at(answer->body, 16);
        for (std::uint32_t v = 0; v < added; ++v)
        {
            const Vec3d p(f32_at(answer->body, 24 + 12 * v), f32_at(answer->body, 28 + 12 * v),
                          f32_at(answer->body, 32 + 12 * v));
            ASSERT_NEAR((origin + p - cloud.origin).norm(), 1.0, 0.01);
        }
        // The server's distances from the samples agree with the reconstruction's report.
        const auto distances = client.Get("/api/layer/1/distance/" + std::to_string(l));
        ASSERT_EQ(status_of(distances), 200);
        EXPECT_EQ(distances->body.substr(0, 4), "PFDS");
        EXPECT_EQ(distances->body.size(),
                  40 + 4 * layer["levels"][l]["vertices"].get<std::size_t>());
        double hausdorff = 0.0;
        std::memcpy(&hausdorff, distances->body.data() + 16, 8);
        EXPECT_NEAR(hausdorff, layer["report"]["levels"][l]["hausdorff"].get<double>(),
                    1e-6 * hausdorff);
    }

    // A fin (three triangles on one edge) is refused with the reason.
    auto fin = nlohmann::json::parse(octahedron_request(cloud));
    fin["triangles"].push_back({fin["triangles"][0][0], fin["triangles"][0][1], 7});
    ASSERT_EQ(status_of(client.Post("/api/reconstruct", fin.dump(), "application/json")), 202);
    const nlohmann::json refused = wait_for_job(client);
    EXPECT_EQ(refused["state"], "failed");
    EXPECT_NE(refused["message"].get<std::string>().find("more than two triangles"),
              std::string::npos)
        << refused.dump();
    EXPECT_EQ(nlohmann::json::parse(client.Get("/api/info")->body)["layers"].size(), 2U);

    EXPECT_EQ(server.stop(SIGINT), 0) << server.output();
}

TEST(ViewCli, CtrlCStopsARunningReconstruction)
{
    test::TempDir dir;
    PointCloud cloud = sphere_samples(400000, Vec3d::Zero());
    const std::string request = octahedron_request(cloud);
    cloud.normals.clear(); // normals to estimate: a reconstruction of several seconds
    write_point_cloud(dir / "sphere.ply", cloud);
    ViewProcess server({(dir / "sphere.ply").string(), "--port", "0"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    auto client = server.client();
    ASSERT_EQ(status_of(client.Post("/api/reconstruct", request, "application/json")), 202);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_EQ(status_of(client.Post("/api/reconstruct", request, "application/json")), 409);
    const auto before = std::chrono::steady_clock::now();
    EXPECT_EQ(server.stop(SIGINT), 0) << server.output();
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count(),
              10.0);
}

TEST(ViewCli, AFileThatCannotBeReadExits3BeforeServing)
{
    test::TempDir dir;
    ViewProcess missing({(dir / "missing.pfh").string(), "--port", "0"});
    EXPECT_EQ(missing.stop(0), 3) << missing.output();
    EXPECT_TRUE(missing.url().empty());
    EXPECT_NE(missing.output().find("missing.pfh"), std::string::npos) << missing.output();

    const auto truncated = dir / "truncated.pfh";
    write_hierarchy(truncated, test::sphere_hierarchy(1));
    std::filesystem::resize_file(truncated, std::filesystem::file_size(truncated) - 5);
    ViewProcess damaged({truncated.string(), "--port", "0"});
    EXPECT_EQ(damaged.stop(0), 3) << damaged.output();
    EXPECT_TRUE(damaged.url().empty());

    ViewProcess bad_port({truncated.string(), "--port", "70000"});
    EXPECT_EQ(bad_port.stop(0), 2) << bad_port.output();

    // A bad file among good ones; more files than a page takes.
    write_hierarchy(dir / "good.pfh", test::sphere_hierarchy(1));
    ViewProcess one_bad({(dir / "good.pfh").string(), truncated.string(), "--port", "0"});
    EXPECT_EQ(one_bad.stop(0), 3) << one_bad.output();
    EXPECT_TRUE(one_bad.url().empty());
    std::vector<std::string> nine(9, (dir / "good.pfh").string());
    nine.insert(nine.end(), {"--port", "0"});
    ViewProcess too_many(nine);
    EXPECT_EQ(too_many.stop(0), 2) << too_many.output();
    EXPECT_NE(too_many.output().find("at most 8"), std::string::npos) << too_many.output();
}

TEST(ViewCli, APortInUseIsReported)
{
    test::TempDir dir;
    write_hierarchy(dir / "sphere.pfh", test::sphere_hierarchy(1));
    ViewProcess first({(dir / "sphere.pfh").string(), "--port", "0"});
    ASSERT_FALSE(first.url().empty()) << first.output();
    ViewProcess second({(dir / "sphere.pfh").string(), "--port", std::to_string(first.port())});
    EXPECT_EQ(second.stop(0), 4) << second.output();
    EXPECT_NE(second.output().find("cannot listen"), std::string::npos) << second.output();
    EXPECT_EQ(first.stop(SIGINT), 0);
}

} // namespace
} // namespace pointform
