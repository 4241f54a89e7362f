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
#include <cstdint>
#include <cstring>
#include <filesystem>
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
    const auto info = nlohmann::json::parse(info_answer->body);
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
        const auto answer = client.Get("/api/level/" + std::to_string(l));
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
    EXPECT_EQ(status_of(client.Get("/api/points")), 404); // a hierarchy has no samples

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

    for (const char* path :
         {"/../../etc/passwd", "/etc/passwd", "/sphere.pfh", "/index.html", "/web/index.html",
          "/viewer/web/index.html", "/vendor/../../CMakeLists.txt", "/%2e%2e/%2e%2e/etc/passwd",
          "/node_modules/three/package.json", "/vendor/three.js", "/api", "/api/level",
          "/api/level/3", "/api/level/99", "/api/level/4294967296000", "/api/level/ 1"})
    {
        SCOPED_TRACE(path);
        const int status = status_of(client.Get(path));
        EXPECT_GE(status, 400);
        EXPECT_LT(status, 500);
        EXPECT_TRUE(still_serving());
    }
    EXPECT_EQ(status_of(client.Get("/api/level/-1")), 400);
    EXPECT_EQ(status_of(client.Get("/api/level/one")), 400);
    EXPECT_EQ(status_of(client.Get("/api/level/99")), 404);

    // Methods other than GET (and HEAD).
    EXPECT_EQ(status_of(client.Post("/api/info", "x", "text/plain")), 405);
    EXPECT_EQ(status_of(client.Put("/", "x", "text/plain")), 405);
    EXPECT_EQ(status_of(client.Delete("/api/level/0")), 405);
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
    EXPECT_EQ(big_body, 413);
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
        const auto info = nlohmann::json::parse(client.Get("/api/info")->body);
        EXPECT_EQ(info["kind"], "points");
        EXPECT_EQ(info["points"], 50);
        EXPECT_EQ(info["colors"], true);
        EXPECT_EQ(info["levels"].size(), 0U);
        const auto points = client.Get("/api/points");
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
        EXPECT_EQ(status_of(client.Get("/api/level/0")), 404);
        EXPECT_EQ(server.stop(SIGINT), 0);
    }

    const TriMesh sphere = test::icosphere(2);
    write_mesh(dir / "sphere.off", sphere);
    ViewProcess server({(dir / "sphere.off").string(), "--port", "0"});
    ASSERT_FALSE(server.url().empty()) << server.output();
    auto client = server.client();
    const auto info = nlohmann::json::parse(client.Get("/api/info")->body);
    EXPECT_EQ(info["kind"], "mesh");
    ASSERT_EQ(info["levels"].size(), 1U);
    EXPECT_EQ(info["levels"][0]["faces"], sphere.face_count());
    const auto level = client.Get("/api/level/0");
    ASSERT_EQ(status_of(level), 200);
    EXPECT_EQ(level->body.size(), 24 + 12 * sphere.vertex_count() + 12 * sphere.face_count());
    EXPECT_EQ(status_of(client.Get("/api/level/1")), 404);
    EXPECT_EQ(server.stop(SIGINT), 0);
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
