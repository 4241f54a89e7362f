// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/io/io.h"

#include "detail_readers.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <system_error>
#include <utility>

namespace pointform {
namespace {

using detail::fail;

/// Closes a FILE* when it goes out of scope (reading only; writers close explicitly).
struct FileCloser
{
    std::FILE* file;
    explicit FileCloser(std::FILE* f) : file(f) {}
    FileCloser(const FileCloser&) = delete;
    FileCloser& operator=(const FileCloser&) = delete;
    ~FileCloser()
    {
        if (file != nullptr)
            std::fclose(file);
    }
};

std::filesystem::path temporary_name(const std::filesystem::path& path)
{
    static std::atomic<unsigned> counter{0};
    static const unsigned seed = std::random_device{}();
    const unsigned tag = seed ^ (counter.fetch_add(1) * 2654435761U);
    char suffix[16];
    std::snprintf(suffix, sizeof(suffix), "%08x", tag);
    std::filesystem::path temp = path;
    temp += ".tmp-";
    temp += suffix;
    return temp;
}

/// Writes through `body` into a temporary file beside `path`, then renames it over `path`.
/// On any failure the temporary file is removed and the exception propagates.
template <typename Body>
void write_atomically(const std::filesystem::path& path, Body&& body)
{
    constexpr int attempts = 8;
    std::filesystem::path temp;
    std::FILE* file = nullptr;
    for (int i = 0; i < attempts && file == nullptr; ++i)
    {
        temp = temporary_name(path);
        file = std::fopen(temp.c_str(), "wbx"); // x: fail rather than reuse an existing name
        if (file == nullptr && errno != EEXIST)
            break;
    }
    if (file == nullptr)
        fail(path, std::string("cannot create the file: ") + std::strerror(errno));

    try
    {
        detail::OutputBuffer out(file, path);
        body(out);
        out.flush();
        std::FILE* done = std::exchange(file, nullptr);
        if (std::fclose(done) != 0)
            fail(path, std::string("write failed: ") + std::strerror(errno));
        std::error_code ec;
        std::filesystem::rename(temp, path, ec);
        if (ec)
            fail(path, "cannot move the temporary file into place: " + ec.message());
    }
    catch (...)
    {
        if (file != nullptr)
            std::fclose(file);
        std::error_code ec;
        std::filesystem::remove(temp, ec);
        throw;
    }
}

FileFormat resolve_format(const std::filesystem::path& path, FileFormat format)
{
    return format == FileFormat::Auto ? format_from_extension(path) : format;
}

} // namespace

void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes)
{
    write_atomically(path, [&](detail::OutputBuffer& out) {
        out.write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
    });
}

std::string format_name(FileFormat format)
{
    switch (format)
    {
        case FileFormat::Auto:
            return "auto";
        case FileFormat::Ply:
            return "ply";
        case FileFormat::Xyz:
            return "xyz";
        case FileFormat::Off:
            return "off";
        case FileFormat::Obj:
            return "obj";
        case FileFormat::Pcd:
            return "pcd";
        case FileFormat::Las:
            return "las";
    }
    return "unknown";
}

FileFormat format_from_extension(const std::filesystem::path& path)
{
    const std::string ext = detail::to_lower(path.extension().string());
    if (ext == ".ply")
        return FileFormat::Ply;
    if (ext == ".xyz" || ext == ".pts" || ext == ".csv" || ext == ".txt" || ext == ".pwn" ||
        ext == ".xyzn")
        return FileFormat::Xyz;
    if (ext == ".off")
        return FileFormat::Off;
    if (ext == ".obj")
        return FileFormat::Obj;
    if (ext == ".pcd")
        return FileFormat::Pcd;
    if (ext == ".las")
        return FileFormat::Las;
    if (ext == ".laz")
        fail(path, "compressed LAZ not supported (decompress it to .las first)");
    if (ext.empty())
        fail(path, "file has no extension, so its format is unknown (set the format option)");
    fail(path, "unknown file extension '" + path.extension().string() + "'");
}

ReadResult read_geometry(const std::filesystem::path& path, const ReadOptions& options)
{
    const FileFormat format = resolve_format(path, options.format);
    const detail::FileBytes bytes = detail::read_whole_file(path);
    const NonFinitePolicy policy = detail::resolve_policy(options.non_finite, format);

    ReadResult result;
    switch (format)
    {
        case FileFormat::Ply:
            result = detail::read_ply(path, bytes, policy);
            break;
        case FileFormat::Xyz:
            result = detail::read_text(path, bytes, policy,
                                       detail::to_lower(path.extension().string()) == ".pts");
            break;
        case FileFormat::Off:
            result = detail::read_off(path, bytes, policy);
            break;
        case FileFormat::Obj:
            result = detail::read_obj(path, bytes, policy);
            break;
        case FileFormat::Pcd:
            result = detail::read_pcd(path, bytes, policy);
            break;
        case FileFormat::Las:
            result = detail::read_las(path, bytes, policy);
            break;
        case FileFormat::Auto:
            fail(path, "no format to read with");
    }
    result.format = format;
    return result;
}

PointCloud read_point_cloud(const std::filesystem::path& path, const ReadOptions& options)
{
    return read_geometry(path, options).points;
}

TriMesh read_mesh(const std::filesystem::path& path, const ReadOptions& options)
{
    ReadResult result = read_geometry(path, options);
    if (result.triangles.empty())
        fail(path, "file has no faces (" + result.description + "), so it is not a mesh");
    return {std::move(result.points), std::move(result.triangles)};
}

void write_point_cloud(const std::filesystem::path& path, const PointCloudView& cloud,
                       const WriteOptions& options)
{
    validate(cloud);
    const FileFormat format = resolve_format(path, options.format);
    if (format != FileFormat::Ply && format != FileFormat::Xyz)
        fail(path, "cannot write point clouds as " + format_name(format) + " (use ply or xyz)");
    write_atomically(path, [&](detail::OutputBuffer& out) {
        if (format == FileFormat::Ply)
            detail::write_ply(out, cloud, {}, options.ascii, options.precision);
        else
            detail::write_xyz(out, cloud, options.precision);
    });
}

void write_mesh(const std::filesystem::path& path, const TriMesh& mesh, const WriteOptions& options)
{
    validate(mesh.vertices);
    const std::size_t n = mesh.vertex_count();
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
        for (const std::uint32_t v : mesh.triangles[f])
            if (v >= n)
                throw InvalidInput("triangle " + std::to_string(f) + " refers to vertex " +
                                   std::to_string(v) + " but the mesh has " + std::to_string(n) +
                                   " vertices");
    const FileFormat format = resolve_format(path, options.format);
    if (format != FileFormat::Ply && format != FileFormat::Off && format != FileFormat::Obj)
        fail(path, "cannot write meshes as " + format_name(format) + " (use ply, off or obj)");
    write_atomically(path, [&](detail::OutputBuffer& out) {
        switch (format)
        {
            case FileFormat::Ply:
                detail::write_ply(out, mesh.vertices, mesh.triangles, options.ascii,
                                  options.precision);
                break;
            case FileFormat::Off:
                detail::write_off(out, mesh, options.precision);
                break;
            default:
                detail::write_obj(out, mesh, options.precision);
                break;
        }
    });
}

namespace detail {

FileBytes read_whole_file(const std::filesystem::path& path)
{
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status))
        fail(path, "file does not exist");
    if (std::filesystem::is_directory(status))
        fail(path, "is a directory, not a file");
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec)
        fail(path, "cannot get the file size: " + ec.message());
    if (size == 0)
        fail(path, "file is empty");

    FileCloser closer{std::fopen(path.c_str(), "rb")};
    if (closer.file == nullptr)
        fail(path, std::string("cannot open file: ") + std::strerror(errno));
    FileBytes bytes(static_cast<std::size_t>(size));
    // Pieces of 8 MiB read at their offsets at once: the copies out of the page cache (and the
    // first touches of the buffer's pages) are shared by the threads.
    constexpr std::size_t piece = std::size_t{1} << 23U;
    const int descriptor = fileno(closer.file);
    std::atomic<std::size_t> short_at{bytes.size()};
    std::atomic<int> error{0};
    parallel_blocks(bytes.size(), piece, [&](std::size_t begin, std::size_t end) {
        std::size_t at = begin;
        while (at < end)
        {
            const ssize_t got =
                ::pread(descriptor, bytes.data() + at, end - at, static_cast<off_t>(at));
            if (got < 0 && errno == EINTR)
                continue;
            if (got <= 0)
            {
                if (got < 0)
                    error.store(errno);
                std::size_t expected = short_at.load();
                while (at < expected && !short_at.compare_exchange_weak(expected, at))
                {}
                return;
            }
            at += static_cast<std::size_t>(got);
        }
    });
    if (error.load() != 0)
        fail(path, std::string("cannot read the file: ") + std::strerror(error.load()));
    if (short_at.load() != bytes.size())
        fail(path, "could not read the whole file (" + std::to_string(short_at.load()) + " of " +
                       std::to_string(bytes.size()) + " bytes)");
    return bytes;
}

} // namespace detail

} // namespace pointform
