// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Pictures of shapes whose projections are known: a sphere seen orthographically is a disc of
// area πr², lit by a headlight its brightness is cos θ = sqrt(1 − ρ²), and so on.

#include "pointform/render/render.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"

#include "support/test_meshes.h"
#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace pointform {
namespace {

bool is_background(const Image& image, int x, int y, const RenderOptions& options)
{
    return image.pixel(x, y) == options.background;
}

/// Pixels that differ from the background.
std::size_t object_pixels(const Image& image, const RenderOptions& options)
{
    std::size_t count = 0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            count += is_background(image, x, y, options) ? 0 : 1;
    return count;
}

/// The orthographic front view (azimuth 0, elevation 0, y up): image x is world x, image y is
/// world −y, and the framing is predictable from the vertices' x and y extents.
struct FrontView
{
    double scale = 0;      ///< pixels per world unit
    double cx = 0, cy = 0; ///< world point at the image centre
    double width = 0, height = 0;

    FrontView(const TriMesh& mesh, const RenderOptions& options)
        : width(options.width), height(options.height)
    {
        double x_min = 1e300, x_max = -1e300, y_min = 1e300, y_max = -1e300;
        for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
        {
            const Vec3d p = mesh.vertices.world(i);
            x_min = std::min(x_min, p.x());
            x_max = std::max(x_max, p.x());
            y_min = std::min(y_min, p.y());
            y_max = std::max(y_max, p.y());
        }
        const double half_y =
            std::max(0.5 * (y_max - y_min), 0.5 * (x_max - x_min) * height / width) /
            (1.0 - options.margin);
        scale = 0.5 * height / half_y;
        cx = 0.5 * (x_min + x_max);
        cy = 0.5 * (y_min + y_max);
    }
    [[nodiscard]] std::pair<double, double> pixel(const Vec3d& p) const
    {
        return {0.5 * width + (p.x() - cx) * scale, 0.5 * height - (p.y() - cy) * scale};
    }
};

RenderOptions front_orthographic()
{
    return {.width = 320,
            .height = 240,
            .azimuth = 0,
            .elevation = 0,
            .projection = Projection::Orthographic};
}

TEST(RenderMesh, SphereSilhouetteIsTheProjectedDisc)
{
    const double r = 2.5;
    const Vec3d center(100.0, -40.0, 7.0); // off the origin: framing must follow the object
    const TriMesh mesh = test::icosphere(4, center, r);
    RenderOptions options = front_orthographic();
    options.supersampling = 1; // count pixel centres inside the silhouette
    const Image image = render_mesh(mesh, options);
    ASSERT_EQ(image.width, 320);
    ASSERT_EQ(image.height, 240);

    const FrontView view(mesh, options);
    const double radius_px = r * view.scale;
    const double area = std::numbers::pi * radius_px * radius_px;
    // The inscribed polyhedron loses well under 0.5% of the disc at this level.
    EXPECT_NEAR(static_cast<double>(object_pixels(image, options)), area, 0.005 * area);

    // Inside the disc: shaded; outside: background, up to a pixel and the facets' sagitta.
    const auto [px, py] = view.pixel(center);
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
        {
            const double d = std::hypot(x + 0.5 - px, y + 0.5 - py);
            if (d < radius_px - 1.5)
            {
                EXPECT_FALSE(is_background(image, x, y, options)) << x << "," << y;
            }
            else if (d > radius_px + 1.0)
            {
                EXPECT_TRUE(is_background(image, x, y, options)) << x << "," << y;
            }
        }
}

TEST(RenderMesh, HeadlightBrightnessIsCosineOfTheViewAngle)
{
    const TriMesh mesh = test::icosphere(4, Vec3d::Zero(), 1.0);
    RenderOptions options = front_orthographic();
    options.ambient = 0.0;
    options.key_light = 0.0;
    options.headlight = 1.0;
    const Image image = render_mesh(mesh, options);
    const FrontView view(mesh, options);
    const auto [px, py] = view.pixel(Vec3d::Zero());
    // Along a diagonal of the image: ρ = distance / radius, brightness = front colour · √(1−ρ²).
    for (const double rho : {0.0, 0.3, 0.6, 0.8, 0.9})
    {
        const double offset = rho * view.scale / std::sqrt(2.0);
        const int x = static_cast<int>(std::floor(px + offset));
        const int y = static_cast<int>(std::floor(py - offset));
        const double true_rho = std::hypot(x + 0.5 - px, y + 0.5 - py) / view.scale;
        const double expected = options.front_color.g * std::sqrt(1.0 - true_rho * true_rho);
        EXPECT_NEAR(image.pixel(x, y).g, expected, 0.02 * options.front_color.g + 1.0)
            << "rho " << true_rho;
    }

    // With the default lights the centre is still brighter than the rim on average.
    const RenderOptions defaults = front_orthographic();
    const Image lit = render_mesh(mesh, defaults);
    const auto brightness = [&](double rho) {
        double sum = 0;
        constexpr int steps = 64;
        for (int k = 0; k < steps; ++k)
        {
            const double angle = 2.0 * std::numbers::pi * k / steps;
            const Color c = lit.pixel(static_cast<int>(px + rho * view.scale * std::cos(angle)),
                                      static_cast<int>(py + rho * view.scale * std::sin(angle)));
            sum += c.r + c.g + c.b;
        }
        return sum / steps;
    };
    EXPECT_GT(brightness(0.0), brightness(0.95) * 1.1);
}

TEST(RenderMesh, BackFacesHaveTheirOwnColour)
{
    // Inside out: every visible face is a back face.
    TriMesh mesh = test::icosphere(3, Vec3d::Zero(), 1.0);
    for (Triangle& t : mesh.triangles)
        std::swap(t[1], t[2]);
    RenderOptions options = front_orthographic();
    options.ambient = 1.0;
    options.key_light = 0.0;
    options.headlight = 0.0;
    const Image inside_out = render_mesh(mesh, options);
    const Color centre = inside_out.pixel(options.width / 2, options.height / 2);
    EXPECT_EQ(centre, options.back_color);

    // A sphere with the cap facing the camera cut away: through the hole, the inside of the far
    // half shows back faces; the remaining rim of the near half shows front faces.
    TriMesh open = test::icosphere(3, Vec3d::Zero(), 1.0);
    std::erase_if(open.triangles, [&](const Triangle& t) {
        double z = 0;
        for (const std::uint32_t v : t)
            z += static_cast<double>(open.vertices.positions[v].z()) / 3.0;
        return z > 0.7;
    });
    const Image holed = render_mesh(open, options);
    EXPECT_EQ(holed.pixel(options.width / 2, options.height / 2), options.back_color);
    const FrontView view(open, options);
    const auto [px, py] = view.pixel(Vec3d(0.0, -0.9, 0.0)); // on the near half, below the hole
    EXPECT_EQ(holed.pixel(static_cast<int>(px), static_cast<int>(py)), options.front_color);
}

TEST(RenderMesh, WireframeDrawsTheEdgesOfVisibleFaces)
{
    const TriMesh mesh = test::icosphere(1, Vec3d::Zero(), 1.0); // 80 faces: large triangles
    RenderOptions options = front_orthographic();
    options.width = options.height = 400;
    const Image plain = render_mesh(mesh, options);
    options.wireframe = true;
    const Image wire = render_mesh(mesh, options);
    const FrontView view(mesh, options);

    const auto luminance = [](const Color& c) {
        return c.r + c.g + c.b;
    };
    std::size_t edges_checked = 0;
    std::size_t centroids_checked = 0;
    for (const Triangle& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.world(t[0]);
        const Vec3d b = mesh.vertices.world(t[1]);
        const Vec3d c = mesh.vertices.world(t[2]);
        const Vec3d normal = (b - a).cross(c - a).normalized();
        if (normal.z() < 0.5) // clearly facing the camera, so its edges are visible
            continue;
        // Midpoint of each edge: a line is drawn there.
        for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}})
        {
            const auto [x, y] = view.pixel(0.5 * (p + q));
            const int ix = static_cast<int>(x);
            const int iy = static_cast<int>(y);
            EXPECT_LT(luminance(wire.pixel(ix, iy)), luminance(plain.pixel(ix, iy)) - 30);
            ++edges_checked;
        }
        // The centroid, many pixels from every edge: untouched.
        const auto [x, y] = view.pixel((a + b + c) / 3.0);
        EXPECT_EQ(wire.pixel(static_cast<int>(x), static_cast<int>(y)),
                  plain.pixel(static_cast<int>(x), static_cast<int>(y)));
        ++centroids_checked;
    }
    EXPECT_GT(edges_checked, 20U);
    EXPECT_GT(centroids_checked, 8U);
    // Outside the silhouette nothing changes.
    EXPECT_EQ(wire.pixel(2, 2), plain.pixel(2, 2));
}

TEST(RenderMesh, WireframeLineWidthIsInPixels)
{
    // Darkened pixels grow with the total projected edge length, not with triangle size: the
    // same sphere at two resolutions darkens about 2× as many pixels per unit of edge length
    // when lines are 2× as wide.
    const TriMesh mesh = test::icosphere(3, Vec3d::Zero(), 1.0);
    RenderOptions options = front_orthographic();
    options.width = options.height = 300;
    const Image plain = render_mesh(mesh, options);
    options.wireframe = true;
    options.line_opacity = 1.0;
    const auto darkening = [&](double width) {
        options.line_width = width;
        const Image wire = render_mesh(mesh, options);
        double sum = 0;
        for (std::size_t i = 0; i < wire.rgb.size(); ++i)
            sum += plain.rgb[i] - wire.rgb[i];
        return sum;
    };
    const double thin = darkening(1.0);
    const double thick = darkening(2.0);
    EXPECT_GT(thin, 0.0);
    EXPECT_NEAR(thick / thin, 2.0, 0.3);
}

TEST(RenderMesh, AFrameFixesTheCameraForSeveralObjects)
{
    // Orthographic front view: a unit sphere framed by the box [-2, 2]³ spans half the height it
    // spans framed by itself, a quarter of the area; moved inside the same frame it keeps its
    // size (the camera stays), and a frame that is not a box is refused.
    RenderOptions options = front_orthographic();
    options.supersampling = 1;
    const auto pixels = [&](const TriMesh& mesh, const RenderOptions& o) {
        return static_cast<double>(object_pixels(render_mesh(mesh, o), o));
    };
    const TriMesh sphere = test::icosphere(4, Vec3d::Zero(), 1.0);
    const double alone = pixels(sphere, options);
    Aabb frame;
    frame.min = Vec3d::Constant(-2.0);
    frame.max = Vec3d::Constant(2.0);
    options.frame = frame;
    const double framed = pixels(sphere, options);
    EXPECT_NEAR(framed / alone, 0.25, 0.01);
    EXPECT_NEAR(pixels(test::icosphere(4, Vec3d(0.5, 0.5, 0.5), 1.0), options), framed,
                0.01 * framed);
    options.frame->min.x() = 3.0;
    EXPECT_THROW((void)render_mesh(sphere, options), InvalidInput);
}

TEST(RenderMesh, PerspectiveFramesTheObject)
{
    // Any view: the object lies within the image, centred, touching the margin on one axis.
    const TriMesh mesh = test::icosphere(3, Vec3d(5, 5, 5), 3.0);
    for (const auto& [azimuth, elevation] :
         {std::pair{30.0, 20.0}, std::pair{-120.0, 60.0}, std::pair{0.0, 90.0}})
    {
        RenderOptions options{
            .width = 300, .height = 200, .azimuth = azimuth, .elevation = elevation};
        options.margin = 0.1;
        const Image image = render_mesh(mesh, options);
        int x_min = image.width, x_max = -1, y_min = image.height, y_max = -1;
        for (int y = 0; y < image.height; ++y)
            for (int x = 0; x < image.width; ++x)
                if (!is_background(image, x, y, options))
                {
                    x_min = std::min(x_min, x);
                    x_max = std::max(x_max, x);
                    y_min = std::min(y_min, y);
                    y_max = std::max(y_max, y);
                }
        ASSERT_GE(x_max, 0);
        // Centred (the sphere's outline is symmetric) and the shorter side filled to 90%.
        EXPECT_NEAR(0.5 * (x_min + x_max + 1), 150.0, 1.5);
        EXPECT_NEAR(0.5 * (y_min + y_max + 1), 100.0, 1.5);
        EXPECT_NEAR(y_max + 1 - y_min, 0.9 * 200, 3.0);
        EXPECT_LT(x_max + 1 - x_min, 0.9 * 300);
    }
}

TEST(RenderMesh, SameImageWhateverTheThreadCount)
{
    const TriMesh mesh = test::icosphere(4, Vec3d::Zero(), 1.0);
    RenderOptions options{.width = 200, .height = 150, .wireframe = true};
    const auto runs = test::at_thread_counts([&] { return render_mesh(mesh, options); });
    EXPECT_EQ(runs[0].rgb, runs[1].rgb);
    EXPECT_EQ(runs[0].rgb, runs[2].rgb);
}

TEST(RenderMesh, RejectsBadInput)
{
    TriMesh mesh = test::icosphere(1, Vec3d::Zero(), 1.0);
    TriMesh no_faces = mesh;
    no_faces.triangles.clear();
    EXPECT_THROW((void)render_mesh(no_faces), InvalidInput);
    EXPECT_THROW((void)render_mesh(TriMesh{}), InvalidInput);

    TriMesh bad_index = mesh;
    bad_index.triangles[3][1] = 1000;
    EXPECT_THROW((void)render_mesh(bad_index), InvalidInput);

    TriMesh nan = mesh;
    nan.vertices.positions[2].x() = std::nanf("");
    EXPECT_THROW((void)render_mesh(nan), InvalidInput);

    for (const RenderOptions& bad :
         {RenderOptions{.width = 0}, RenderOptions{.height = -3}, RenderOptions{.elevation = 91},
          RenderOptions{.up = Vec3d::Zero()}, RenderOptions{.field_of_view = 180},
          RenderOptions{.supersampling = 0}, RenderOptions{.line_width = 0}})
        EXPECT_THROW((void)render_mesh(mesh, bad), InvalidInput);
}

TEST(RenderMesh, DegenerateMeshesStillRender)
{
    // One triangle seen edge-on draws nothing but does not fail; a flat one seen face-on draws.
    TriMesh flat;
    flat.vertices.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    flat.triangles = {{0, 1, 2}};
    RenderOptions options = front_orthographic();
    EXPECT_GT(object_pixels(render_mesh(flat, options), options), 0U);
    options.azimuth = 90;
    EXPECT_EQ(object_pixels(render_mesh(flat, options), options), 0U);
}

TEST(RenderPoints, SphereSamplesCoverTheDisc)
{
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 20000});
    RenderOptions options = front_orthographic();
    options.supersampling = 1;
    const Image image = render_points(cloud, options);
    // Framed by the samples' extents, which reach the unit sphere to within the spacing.
    const double scale = 0.5 * options.height * (1.0 - options.margin);
    const double area = std::numbers::pi * scale * scale;
    // Discs reach past the silhouette by up to a disc radius (spacing ≈ 0.025): a few percent.
    EXPECT_NEAR(static_cast<double>(object_pixels(image, options)), area, 0.06 * area);
    // No holes inside the disc.
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            if (std::hypot(x + 0.5 - 160.0, y + 0.5 - 120.0) < 0.97 * scale)
            {
                ASSERT_FALSE(is_background(image, x, y, options)) << x << "," << y;
            }
}

TEST(RenderPoints, ShadedByNormal)
{
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 8000});
    RenderOptions options = front_orthographic();
    options.ambient = 0.0;
    options.key_light = 0.0;
    options.headlight = 1.0;
    const Image image = render_points(cloud, options);
    const double scale = 0.5 * options.height * (1.0 - options.margin);
    for (const double rho : {0.0, 0.5, 0.8})
    {
        const int x = static_cast<int>(160.0 + rho * scale);
        const double expected = options.front_color.g * std::sqrt(1.0 - rho * rho);
        // Each disc is flat, shaded by its sample's normal: within the spacing's angle.
        EXPECT_NEAR(image.pixel(x, 120).g, expected, 0.05 * options.front_color.g) << rho;
    }

    // Inward normals: back colour.
    PointCloud inward = cloud;
    for (Vec3f& n : inward.normals)
        n = -n;
    options.ambient = 1.0;
    options.headlight = 0.0;
    EXPECT_EQ(render_points(inward, options).pixel(160, 120), options.back_color);
}

TEST(RenderPoints, WithoutNormalsEstimatesOrDrawsFlat)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 5000});
    cloud.normals.clear();
    RenderOptions options = front_orthographic();
    options.ambient = 1.0;
    options.key_light = 0.0;
    options.headlight = 0.0;
    // Estimated and oriented outward (compute_surfels): front colour at the centre.
    EXPECT_EQ(render_points(cloud, options).pixel(160, 120), options.front_color);

    // Flat: every covered pixel (full coverage, away from the outline) has one colour.
    options.estimate_normals = false;
    options.ambient = 0.3;
    options.key_light = 0.6;
    const Image flat = render_points(cloud, options);
    const Color centre = flat.pixel(160, 120);
    EXPECT_NE(centre, options.background);
    EXPECT_EQ(flat.pixel(180, 100), centre);
    EXPECT_EQ(flat.pixel(120, 150), centre);
}

TEST(RenderPoints, SplatRadiusOptions)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 500});
    RenderOptions options = front_orthographic();
    const Image automatic = render_points(cloud, options);
    // Tiny fixed discs leave most of the silhouette empty.
    options.splat_radius = 0.002;
    const Image tiny = render_points(cloud, options);
    EXPECT_LT(object_pixels(tiny, options), object_pixels(automatic, options) / 4);
    // The cloud's own radii, when asked for: the same tiny discs.
    options.splat_radius = 0.0;
    cloud.radii.assign(cloud.size(), 0.002F);
    options.use_radii = true;
    EXPECT_EQ(render_points(cloud, options).rgb, tiny.rgb);
    // Otherwise the radii play no part.
    options.use_radii = false;
    EXPECT_EQ(render_points(cloud, options).rgb, automatic.rgb);
    // splat_scale multiplies every radius.
    options.splat_scale = 0.1;
    EXPECT_LT(object_pixels(render_points(cloud, options), options),
              object_pixels(automatic, options) / 4);
}

TEST(RenderPoints, SinglePointAndDuplicates)
{
    PointCloud one;
    one.positions = {{1, 2, 3}};
    const RenderOptions options = front_orthographic();
    EXPECT_GT(object_pixels(render_points(one, options), options), 0U);
    PointCloud same;
    same.positions.assign(50, Vec3f(1, 2, 3));
    EXPECT_GT(object_pixels(render_points(same, options), options), 0U);
}

TEST(RenderPoints, SameImageWhateverTheThreadCount)
{
    PointCloud cloud = sample_shape(Shape::Torus, {.count = 8000});
    const RenderOptions options{.width = 200, .height = 150};
    const auto runs = test::at_thread_counts([&] { return render_points(cloud, options); });
    EXPECT_EQ(runs[0].rgb, runs[1].rgb);
    EXPECT_EQ(runs[0].rgb, runs[2].rgb);
}

TEST(RenderPoints, RejectsBadInput)
{
    EXPECT_THROW((void)render_points(PointCloud{}), InvalidInput);
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 100});
    cloud.normals.pop_back();
    EXPECT_THROW((void)render_points(cloud), InvalidInput);
    PointCloud nan = sample_shape(Shape::Sphere, {.count = 100});
    nan.positions[5].y() = std::numeric_limits<float>::infinity();
    EXPECT_THROW((void)render_points(nan), InvalidInput);
    EXPECT_THROW((void)render_points(sample_shape(Shape::Sphere, {.count = 100}),
                                     RenderOptions{.splat_scale = 0}),
                 InvalidInput);
    // Too many samples for the depth buffer: refused before allocating.
    EXPECT_THROW((void)render_points(sample_shape(Shape::Sphere, {.count = 100}),
                                     RenderOptions{.width = 16384, .height = 16384}),
                 InvalidInput);
}

TEST(Png, WritesAReadableHeader)
{
    test::TempDir dir;
    Image image{.width = 7, .height = 5, .rgb = std::vector<std::uint8_t>(7 * 5 * 3, 200)};
    const auto path = dir / "tiny.png";
    write_png(path, image);
    const std::string bytes = test::read_file(path);
    ASSERT_GE(bytes.size(), 24U);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    const auto be32 = [&](std::size_t at) {
        return (static_cast<unsigned>(static_cast<unsigned char>(bytes[at])) << 24U) |
               (static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 1])) << 16U) |
               (static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 2])) << 8U) |
               static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 3]));
    };
    EXPECT_EQ(be32(16), 7U);
    EXPECT_EQ(be32(20), 5U);
    // No temporary file left beside it.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              1);
}

TEST(Png, RejectsBadImagesAndPaths)
{
    Image bad{.width = 4, .height = 4, .rgb = std::vector<std::uint8_t>(10)};
    EXPECT_THROW((void)encode_png(bad), InvalidInput);
    EXPECT_THROW((void)encode_png(Image{}), InvalidInput);
    test::TempDir dir;
    const Image ok{.width = 2, .height = 2, .rgb = std::vector<std::uint8_t>(12)};
    EXPECT_THROW(write_png(dir / "missing" / "x.png", ok), IoError);
}

} // namespace
} // namespace pointform
