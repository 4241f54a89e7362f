// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/render/render.h"
#include "pointform/spatial/triangle_bvh.h"

#include "detail_render.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace pointform {
namespace {

/// Owns an Embree device and turns its errors into pointform::Error.
class EmbreeDevice
{
public:
    EmbreeDevice()
    {
        const std::string config = "verbose=0,threads=" + std::to_string(thread_count());
        device_ = rtcNewDevice(config.c_str());
        if (device_ == nullptr)
            throw Error("Embree: cannot create a device (" +
                        std::string(describe(rtcGetDeviceError(nullptr))) + ")");
        rtcSetDeviceErrorFunction(device_, &EmbreeDevice::on_error, this);
    }
    ~EmbreeDevice() { rtcReleaseDevice(device_); }
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    [[nodiscard]] RTCDevice get() const { return device_; }

    /// Throws the first error Embree reported since the last check.
    void check(const char* call)
    {
        const RTCError code = rtcGetDeviceError(device_);
        if (code == RTC_ERROR_NONE && message_.empty())
            return;
        std::string message = message_.empty() ? describe(code) : message_;
        message_.clear();
        throw Error(std::string("Embree: ") + call + " failed: " + message);
    }

private:
    static const char* describe(RTCError code)
    {
        switch (code)
        {
            case RTC_ERROR_NONE:
                return "no error";
            case RTC_ERROR_INVALID_ARGUMENT:
                return "invalid argument";
            case RTC_ERROR_INVALID_OPERATION:
                return "invalid operation";
            case RTC_ERROR_OUT_OF_MEMORY:
                return "out of memory";
            case RTC_ERROR_UNSUPPORTED_CPU:
                return "unsupported CPU";
            case RTC_ERROR_CANCELLED:
                return "cancelled";
            default:
                return "unknown error";
        }
    }
    static void on_error(void* user, RTCError code, const char* text)
    {
        auto* self = static_cast<EmbreeDevice*>(user);
        if (self->message_.empty())
            self->message_ = std::string(describe(code)) + (text != nullptr ? ": " : "") +
                             (text != nullptr ? text : "");
    }

    RTCDevice device_ = nullptr;
    std::string message_;
};

/// Owns an Embree scene.
class EmbreeScene
{
public:
    explicit EmbreeScene(RTCDevice device) : scene_(rtcNewScene(device)) {}
    ~EmbreeScene()
    {
        if (scene_ != nullptr)
            rtcReleaseScene(scene_);
    }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    [[nodiscard]] RTCScene get() const { return scene_; }

private:
    RTCScene scene_;
};

/// Distance, in pixels, from image point p to the line through a and b (to a if they coincide).
double line_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
{
    const Eigen::Vector2d edge = b - a;
    const double length = edge.norm();
    if (length < 1e-12)
        return (p - a).norm();
    const Eigen::Vector2d d = p - a;
    return std::abs(edge.x() * d.y() - edge.y() * d.x()) / length;
}

void check_mesh(const TriMesh& mesh)
{
    if (mesh.triangles.empty())
        throw InvalidInput("render_mesh: the mesh has no triangles (" +
                           std::to_string(mesh.vertex_count()) +
                           " vertices); render them as points with render_points");
    const std::size_t n = mesh.vertex_count();
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
        for (const std::uint32_t v : mesh.triangles[f])
            if (v >= n)
                throw InvalidInput("render_mesh: triangle " + std::to_string(f) +
                                   " refers to vertex " + std::to_string(v) + " of " +
                                   std::to_string(n));
    for (std::size_t i = 0; i < n; ++i)
        if (!mesh.vertices.positions[i].allFinite())
            throw InvalidInput("render_mesh: vertex " + std::to_string(i) + " is not finite");
    if (!mesh.vertices.origin.allFinite())
        throw InvalidInput("render_mesh: the origin is not finite");
}

/// A texture on the faces: per-vertex texture coordinates, the colour image, and optionally a
/// tangent-space normal map with the vertices' normals and tangent frames.
struct Texturing
{
    std::span<const Vec2f> uvs;
    const TextureImage* color = nullptr;
    const TextureImage* normal_map = nullptr;
    std::span<const Vec3f> normals;
    std::span<const Eigen::Vector4f> tangents;
};

Image render_surface(const TriMesh& mesh, const RenderOptions& options, const Texturing* texturing);

} // namespace

Image render_mesh(const TriMesh& mesh, const RenderOptions& options)
{
    return render_surface(mesh, options, nullptr);
}

Image render_textured_mesh(const TexturedMesh& mesh, std::size_t lod, const RenderOptions& options)
{
    if (lod >= mesh.lods.size())
        throw InvalidInput("render_textured_mesh: level of detail " + std::to_string(lod) +
                           " does not exist (the mesh has " + std::to_string(mesh.lods.size()) +
                           ")");
    const std::size_t n = mesh.lod_vertex_counts.at(lod);
    if (mesh.uvs.size() < n || mesh.positions.size() < n || mesh.base_color.empty())
        throw InvalidInput(
            "render_textured_mesh: the mesh needs positions, texture coordinates "
            "and a colour texture");
    const bool normal_mapped =
        !mesh.normal_map.empty() && mesh.normals.size() >= n && mesh.tangents.size() >= n;
    TriMesh triangles;
    triangles.vertices.origin = mesh.origin;
    triangles.vertices.positions.assign(mesh.positions.begin(),
                                        mesh.positions.begin() + static_cast<std::ptrdiff_t>(n));
    triangles.triangles = mesh.lods[lod];
    Texturing texturing;
    texturing.uvs = std::span(mesh.uvs).first(n);
    texturing.color = &mesh.base_color;
    if (normal_mapped)
    {
        texturing.normal_map = &mesh.normal_map;
        texturing.normals = std::span(mesh.normals).first(n);
        texturing.tangents = std::span(mesh.tangents).first(n);
    }
    return render_surface(triangles, options, &texturing);
}

namespace {

Image render_surface(const TriMesh& mesh, const RenderOptions& options, const Texturing* texturing)
{
    validate(options);
    check_mesh(mesh);
    const std::size_t rays = static_cast<std::size_t>(options.width) *
                             static_cast<std::size_t>(options.height) *
                             static_cast<std::size_t>(options.supersampling) *
                             static_cast<std::size_t>(options.supersampling);
    // Embree tests four or eight boxes at once: a 100,000-gon's 5e10 estimated tests took 64
    // CPU-seconds, so rays get ten times the closest-point queries' budget.
    check_query_work(mesh, rays, "render_mesh", 1e10);

    // Local coordinates about the centre of the box of the vertices that faces use.
    const std::size_t vertex_count = mesh.vertex_count();
    std::vector<char> used(vertex_count, 0);
    for (const Triangle& t : mesh.triangles)
        for (const std::uint32_t v : t)
            used[v] = 1;
    Aabb box;
    for (std::size_t i = 0; i < vertex_count; ++i)
        if (used[i] != 0)
            box.extend(mesh.vertices.world(i));
    if (options.frame)
        box = *options.frame;
    const Vec3d shift = mesh.vertices.origin - box.center();
    // Embree reads vertices with 16-byte loads: one float of padding after the last.
    std::vector<float> vertices(3 * vertex_count + 1, 0.0F);
    std::vector<Vec3f> fit_points;
    fit_points.reserve(vertex_count);
    for (std::size_t i = 0; i < vertex_count; ++i)
    {
        const Vec3f p = (mesh.vertices.positions[i].cast<double>() + shift).cast<float>();
        vertices[3 * i] = p.x();
        vertices[3 * i + 1] = p.y();
        vertices[3 * i + 2] = p.z();
        if (used[i] != 0)
            fit_points.push_back(p);
    }
    const auto vertex = [&](std::uint32_t v) {
        return Vec3d(vertices[3 * std::size_t{v}], vertices[3 * std::size_t{v} + 1],
                     vertices[3 * std::size_t{v} + 2]);
    };
    const std::size_t face_count = mesh.face_count();
    std::vector<std::uint32_t> indices(3 * face_count + 1, 0);
    for (std::size_t f = 0; f < face_count; ++f)
        std::copy(mesh.triangles[f].begin(), mesh.triangles[f].end(), indices.begin() + 3 * f);

    if (options.frame)
        fit_points = detail::box_corners(*options.frame);
    const detail::Camera camera = detail::fit_camera(fit_points, options);
    fit_points = {};

    // Face normals (unit, counter-clockwise side) and area-weighted vertex normals.
    std::vector<Vec3f> face_normals(face_count, Vec3f::Zero());
    std::vector<Vec3d> vertex_normals(options.smooth_shading ? vertex_count : 0, Vec3d::Zero());
    for (std::size_t f = 0; f < face_count; ++f)
    {
        const Triangle& t = mesh.triangles[f];
        const Vec3d a = vertex(t[0]);
        const Vec3d weighted = (vertex(t[1]) - a).cross(vertex(t[2]) - a);
        const double norm = weighted.norm();
        if (norm > 0.0)
            face_normals[f] = (weighted / norm).cast<float>();
        if (options.smooth_shading)
            for (const std::uint32_t v : t)
                vertex_normals[v] += weighted;
    }
    for (Vec3d& n : vertex_normals)
        n.normalize(); // Eigen leaves a zero vector unchanged

    EmbreeDevice device;
    EmbreeScene scene(device.get());
    device.check("rtcNewScene");
    {
        RTCGeometry geometry = rtcNewGeometry(device.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
        device.check("rtcNewGeometry");
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                   vertices.data(), 0, 3 * sizeof(float), vertex_count);
        rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                   indices.data(), 0, 3 * sizeof(std::uint32_t), face_count);
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene.get(), geometry);
        rtcReleaseGeometry(geometry);
        device.check("building the geometry");
    }
    rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitScene(scene.get());
    device.check("rtcCommitScene");

    Image image = detail::make_image(options);
    const int s = options.supersampling;
    const Vec3d background = detail::to_vec(options.background);
    const Vec3d line_color = detail::to_vec(options.line_color);
    const double half_line = 0.5 * options.line_width;
    const auto to_2d = [&](const Vec3d& p) {
        const Vec3d q = camera.project(p);
        return Eigen::Vector2d(q.x(), q.y());
    };

    parallel_blocks(
        static_cast<std::size_t>(options.height), 1, [&](std::size_t begin, std::size_t end) {
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            for (std::size_t row = begin; row < end; ++row)
                for (int x = 0; x < options.width; ++x)
                {
                    Vec3d sum = Vec3d::Zero();
                    for (int j = 0; j < s; ++j)
                        for (int i = 0; i < s; ++i)
                        {
                            const double sx = x + (i + 0.5) / s;
                            const double sy = static_cast<double>(row) + (j + 0.5) / s;
                            Vec3d origin, direction;
                            camera.ray(sx, sy, origin, direction);
                            RTCRayHit hit{};
                            hit.ray.org_x = static_cast<float>(origin.x());
                            hit.ray.org_y = static_cast<float>(origin.y());
                            hit.ray.org_z = static_cast<float>(origin.z());
                            hit.ray.dir_x = static_cast<float>(direction.x());
                            hit.ray.dir_y = static_cast<float>(direction.y());
                            hit.ray.dir_z = static_cast<float>(direction.z());
                            hit.ray.tnear = 0.0F;
                            hit.ray.tfar = std::numeric_limits<float>::infinity();
                            hit.ray.mask = std::numeric_limits<unsigned>::max();
                            hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                            hit.hit.primID = RTC_INVALID_GEOMETRY_ID;
                            rtcIntersect1(scene.get(), &context, &hit);
                            if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID)
                            {
                                sum += background;
                                continue;
                            }
                            const std::size_t f = hit.hit.primID;
                            const Triangle& t = mesh.triangles[f];
                            const Vec3d face_normal = face_normals[f].cast<double>();
                            const bool front = face_normal.dot(direction) < 0.0;
                            Vec3d normal = face_normal;
                            if (options.smooth_shading)
                            {
                                const double u = hit.hit.u;
                                const double v = hit.hit.v;
                                const Vec3d interpolated = (1.0 - u - v) * vertex_normals[t[0]] +
                                                           u * vertex_normals[t[1]] +
                                                           v * vertex_normals[t[2]];
                                // Keep the facet's side: a smooth normal never flips a face.
                                if (interpolated.dot(face_normal) > 0.0)
                                    normal = interpolated.normalized();
                            }
                            Vec3d color;
                            if (texturing != nullptr && front)
                            {
                                const double u = hit.hit.u;
                                const double v = hit.hit.v;
                                const auto corner = [&](auto values, int k) {
                                    return values[t[static_cast<std::size_t>(k)]]
                                        .template cast<double>();
                                };
                                const Eigen::Vector2d uv =
                                    (1.0 - u - v) * corner(texturing->uvs, 0) +
                                    u * corner(texturing->uvs, 1) + v * corner(texturing->uvs, 2);
                                if (texturing->normal_map != nullptr)
                                {
                                    // The glTF tangent frame: +x along the tangent, +y the
                                    // bitangent cross(n, t) · w, +z the interpolated normal.
                                    Vec3d n = ((1.0 - u - v) * corner(texturing->normals, 0) +
                                               u * corner(texturing->normals, 1) +
                                               v * corner(texturing->normals, 2))
                                                  .normalized();
                                    Vec3d tangent = Vec3d::Zero();
                                    for (int k = 0; k < 3; ++k)
                                        tangent +=
                                            (k == 0   ? 1.0 - u - v
                                             : k == 1 ? u
                                                      : v) *
                                            texturing->tangents[t[static_cast<std::size_t>(k)]]
                                                .head<3>()
                                                .cast<double>();
                                    tangent -= tangent.dot(n) * n;
                                    if (tangent.norm() > 0.0)
                                    {
                                        tangent.normalize();
                                        const Vec3d bitangent =
                                            n.cross(tangent) *
                                            static_cast<double>(texturing->tangents[t[0]].w());
                                        const Vec3d m =
                                            sample_texture(*texturing->normal_map, uv) / 127.5 -
                                            Vec3d::Ones();
                                        const Vec3d mapped =
                                            m.x() * tangent + m.y() * bitangent + m.z() * n;
                                        if (mapped.norm() > 0.0)
                                            normal = mapped.normalized();
                                    }
                                }
                                color = sample_texture(*texturing->color, uv) *
                                        detail::shade_intensity(camera, options, normal, direction);
                            }
                            else
                                color = detail::shade(camera, options, normal, direction, front);
                            if (options.wireframe)
                            {
                                const Eigen::Vector2d p(sx, sy);
                                const Eigen::Vector2d a = to_2d(vertex(t[0]));
                                const Eigen::Vector2d b = to_2d(vertex(t[1]));
                                const Eigen::Vector2d c = to_2d(vertex(t[2]));
                                const double distance =
                                    std::min({line_distance(p, a, b), line_distance(p, b, c),
                                              line_distance(p, c, a)});
                                // Coverage of a line of the given width, with a one-pixel ramp.
                                const double coverage =
                                    std::clamp(half_line + 0.5 - distance, 0.0, 1.0);
                                const double alpha = options.line_opacity * coverage;
                                color = (1.0 - alpha) * color + alpha * line_color;
                            }
                            sum += color;
                        }
                    detail::store_pixel(image, x, static_cast<int>(row), sum, s * s);
                }
        });
    return image;
}

} // namespace
} // namespace pointform
