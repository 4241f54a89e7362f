// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The parameterization over the base mesh, the atlas and the textures baked through it (§5.3,
// Fig. 12): exact dyadic coordinates, charts without flips or overlaps, an isometric map of a
// flat hierarchy, colours and normals baked back where they came from.

#include "pointform/multires/texture.h"

#include "pointform/core/error.h"
#include "pointform/multires/atlas.h"
#include "pointform/multires/details.h"
#include "pointform/multires/parameterization.h"

#include "multires_fixtures.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace pointform {
namespace {

/// The hierarchy with every detail zero: each new vertex at its edge's midpoint.
MultiresMesh without_details(const MultiresMesh& mesh)
{
    MultiresMesh flat = mesh;
    MultiresDetails details = analyze_details(flat);
    for (Vec3d& d : details.coefficients)
        d = Vec3d::Zero();
    synthesize_details(flat, details, 0);
    return flat;
}

Vec3d interpolate_base(const MultiresMesh& mesh, std::uint32_t face, const Vec3d& b)
{
    const Triangle& t = mesh.base_faces()[face];
    return b.x() * mesh.positions()[t[0]] + b.y() * mesh.positions()[t[1]] +
           b.z() * mesh.positions()[t[2]];
}

TEST(Parameterization, DyadicCoordinatesGiveTheMidpointHierarchyBack)
{
    const MultiresMesh mesh = without_details(test::relief_sphere(4));
    const Parameterization p(mesh);
    ASSERT_EQ(p.coordinates().size(), mesh.vertex_count());
    const double tolerance = 1e-12 * test::diagonal(mesh);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const BaseCoordinates& c = p.coordinates()[v];
        const Vec3d& b = c.barycentric;
        EXPECT_GE(b.minCoeff(), 0.0);
        EXPECT_EQ(b.sum(), 1.0) << "vertex " << v; // dyadic: exact
        // Exact dyadic values with denominator 2^level.
        const double scale = std::ldexp(1.0, static_cast<int>(mesh.level_of_vertex(v)));
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(std::round(b[k] * scale), b[k] * scale);
        EXPECT_LE((interpolate_base(mesh, c.face, b) - mesh.positions()[v]).norm(), tolerance);
    }
    // Every corner of every finest face, in its face's base face (seams included).
    const std::size_t level = mesh.finest_level();
    const std::vector<Triangle> faces = mesh.faces(level);
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (const std::uint32_t v : faces[f])
        {
            const auto chart = static_cast<std::uint32_t>(f >> (2 * level));
            EXPECT_LE(
                (interpolate_base(mesh, chart, p.coordinates_in(chart, v)) - mesh.positions()[v])
                    .norm(),
                tolerance);
        }
    EXPECT_THROW((void)p.coordinates_in(70, 0), InvalidInput); // vertex 0 is not on face 70
}

TEST(Parameterization, LocateFindsTheSubTriangle)
{
    const MultiresMesh mesh = test::relief_sphere(3);
    const Parameterization p(mesh);
    std::vector<std::vector<Triangle>> faces;
    for (std::size_t level = 0; level <= 3; ++level)
        faces.push_back(mesh.faces(level));
    std::mt19937 random(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 500; ++trial)
    {
        double a = unit(random);
        double b = unit(random);
        if (a + b > 1.0)
        {
            a = 1.0 - a;
            b = 1.0 - b;
        }
        const Vec3d beta(a, b, 1.0 - a - b);
        const auto face = static_cast<std::uint32_t>(trial % mesh.base_faces().size());
        for (std::size_t level = 0; level <= 3; ++level)
        {
            const Parameterization::Location at = Parameterization::locate(face, beta, level);
            EXPECT_EQ(at.face >> (2 * level), face);
            EXPECT_GE(at.barycentric.minCoeff(), -1e-12);
            const Triangle& t = faces[level][at.face];
            Vec3d back = Vec3d::Zero();
            for (int k = 0; k < 3; ++k)
                back += at.barycentric[k] * p.coordinates_in(face, t[static_cast<std::size_t>(k)]);
            EXPECT_LE((back - beta).norm(), 1e-12);
        }
    }
}

TEST(Atlas, ChartsNeitherFlipNorOverlapAndAFlatHierarchyIsIsometric)
{
    for (const bool flat : {false, true})
    {
        SCOPED_TRACE(flat ? "flat plate" : "bumpy sphere");
        const MultiresMesh mesh =
            flat ? without_details(MultiresMesh(test::square_grid(6))) : test::relief_sphere(3);
        MultiresMesh refined = mesh;
        if (flat)
            for (int l = 0; l < 3; ++l)
            {
                (void)refined.split(); // midpoints: still flat
            }
        const Parameterization p(refined);
        const Atlas atlas = make_atlas(refined, refined.finest_level(), {.size = 512, .gutter = 3});
        EXPECT_EQ(atlas.size, 512);
        EXPECT_GT(atlas.texel_usage, 0.2);
        // Charts inside the texture and at least a gutter apart (triangles may interleave, so
        // the distance between the triangles themselves).
        const std::size_t charts = atlas.corners.size();
        std::vector<std::array<Vec2d, 3>> texel(charts);
        for (std::size_t i = 0; i < charts; ++i)
            for (std::size_t k = 0; k < 3; ++k)
            {
                texel[i][k] = atlas.corners[i][k] * atlas.size;
                EXPECT_GE(texel[i][k].minCoeff(), 0.5 * atlas.gutter - 1e-9);
                EXPECT_LE(texel[i][k].maxCoeff(), atlas.size - 0.5 * atlas.gutter + 1e-9);
            }
        const auto segment_distance = [](const Vec2d& p, const Vec2d& a, const Vec2d& b) {
            const Vec2d ab = b - a;
            const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
            return (a + t * ab - p).norm();
        };
        const auto inside = [](const Vec2d& p, const std::array<Vec2d, 3>& t) {
            const auto side = [](const Vec2d& a, const Vec2d& b, const Vec2d& q) {
                return (b - a).x() * (q - a).y() - (b - a).y() * (q - a).x();
            };
            const double s0 = side(t[0], t[1], p);
            const double s1 = side(t[1], t[2], p);
            const double s2 = side(t[2], t[0], p);
            return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
        };
        const auto distance = [&](const std::array<Vec2d, 3>& a, const std::array<Vec2d, 3>& b) {
            double d = std::numeric_limits<double>::infinity();
            const auto cross = [](const Vec2d& p, const Vec2d& q, const Vec2d& r) {
                return (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
            };
            for (std::size_t k = 0; k < 3; ++k)
            {
                if (inside(a[k], b) || inside(b[k], a))
                    return 0.0;
                for (std::size_t e = 0; e < 3; ++e) // edges that cross
                {
                    const Vec2d& p = a[k];
                    const Vec2d& q = a[(k + 1) % 3];
                    const Vec2d& r = b[e];
                    const Vec2d& t = b[(e + 1) % 3];
                    if (cross(p, q, r) * cross(p, q, t) < 0 && cross(r, t, p) * cross(r, t, q) < 0)
                        return 0.0;
                }
                for (std::size_t e = 0; e < 3; ++e)
                {
                    d = std::min(d, segment_distance(a[k], b[e], b[(e + 1) % 3]));
                    d = std::min(d, segment_distance(b[k], a[e], a[(e + 1) % 3]));
                }
            }
            return d; // segments of two triangles that do not contain each other's corners
        };
        std::size_t too_close = 0;
        for (std::size_t i = 0; i < charts; ++i)
            for (std::size_t j = i + 1; j < charts; ++j)
                if (distance(texel[i], texel[j]) < atlas.gutter - 1e-6)
                    ++too_close;
        EXPECT_EQ(too_close, 0U);
        const std::vector<std::size_t> levels = {0, refined.finest_level()};
        for (const AtlasDistortion& d : atlas_distortion(refined, p, atlas, levels))
        {
            EXPECT_EQ(d.flipped, 0U);
            EXPECT_GE(d.l2_stretch, 1.0 - 1e-9);
            EXPECT_GE(d.linf_stretch, d.l2_stretch - 1e-9);
            if (flat)
            {
                EXPECT_NEAR(d.l2_stretch, 1.0, 1e-9);
                EXPECT_NEAR(d.angle_distortion, 0.0, 1e-6);
                EXPECT_NEAR(d.area_distortion, 0.0, 1e-6);
            }
            else
            {
                EXPECT_LT(d.l2_stretch, 1.5);
            }
        }
    }
}

TEST(Atlas, TexturedLevelsArePrefixesWithSeamsOnBaseEdges)
{
    const MultiresMesh mesh = test::relief_sphere(3, Predictor::Butterfly);
    const Parameterization p(mesh);
    const Atlas atlas = make_atlas(mesh, 3);
    const std::vector<std::size_t> levels = {0, 1, 3};
    const TexturedMesh t = textured_levels(mesh, p, atlas, levels);
    ASSERT_EQ(t.lods.size(), 3U);
    ASSERT_EQ(t.lod_vertex_counts.size(), 3U);
    EXPECT_EQ(t.lod_vertex_counts.back(), t.positions.size());
    EXPECT_GT(t.positions.size(), mesh.vertex_count()); // seam vertices duplicated per chart
    for (std::size_t i = 0; i < 3; ++i)
    {
        EXPECT_EQ(t.lods[i].size(), mesh.face_count(levels[i]));
        if (i > 0)
            EXPECT_GT(t.lod_vertex_counts[i], t.lod_vertex_counts[i - 1]);
        for (const Triangle& tri : t.lods[i])
        {
            for (const std::uint32_t v : tri)
                EXPECT_LT(v, t.lod_vertex_counts[i]);
            const Vec2f a = t.uvs[tri[1]] - t.uvs[tri[0]];
            const Vec2f b = t.uvs[tri[2]] - t.uvs[tri[0]];
            EXPECT_LT(a.x() * b.y() - a.y() * b.x(), 0.0f); // counter-clockwise with v up
        }
    }
    for (std::size_t v = 0; v < t.positions.size(); ++v)
    {
        EXPECT_GE(t.uvs[v].minCoeff(), 0.0f);
        EXPECT_LE(t.uvs[v].maxCoeff(), 1.0f);
        EXPECT_NEAR(t.normals[v].norm(), 1.0f, 1e-5f);
        EXPECT_NEAR(t.tangents[v].head<3>().dot(t.normals[v]), 0.0f, 1e-5f);
    }
    EXPECT_THROW((void)textured_levels(mesh, p, atlas, std::vector<std::size_t>{2, 1}),
                 InvalidInput);
    EXPECT_THROW((void)make_atlas(mesh, 3, {.size = 8}), InvalidInput);
    EXPECT_THROW((void)make_atlas(mesh, 9), InvalidInput);
}

/// A colour that varies smoothly over space.
Color colour_at(const Vec3d& p)
{
    const auto channel = [](double x) {
        return static_cast<std::uint8_t>(std::lround(127.5 + 120.0 * std::sin(x)));
    };
    return {channel(2.0 * p.x()), channel(2.0 * p.y() + 1.0), channel(2.0 * p.z() + 2.0)};
}

TEST(Texture, BakedColoursComeBackAtTheSurface)
{
    const MultiresMesh mesh = test::relief_sphere(4);
    const Parameterization p(mesh);
    const Atlas atlas = make_atlas(mesh, 4, {.size = 1024});
    // Samples on the surface: the finest level's vertices and face centres, coloured.
    PointCloud samples;
    const std::vector<Triangle> faces = mesh.faces(4);
    for (const Triangle& t : faces)
    {
        const Vec3d c = (mesh.world(t[0]) + mesh.world(t[1]) + mesh.world(t[2])) / 3.0;
        samples.positions.push_back(c.cast<float>());
        samples.colors.push_back(colour_at(c));
    }
    BakeReport report;
    const TextureImage image = bake_colors(mesh, p, atlas, 4, samples, {}, &report);
    EXPECT_GT(report.texels, 0U);
    EXPECT_GT(report.dilated, 0U);
    EXPECT_LT(report.rms_color_error, 6.0);
    // At every vertex of level 2 (inside the charts), the texture shows the vertex's colour.
    double worst = 0.0;
    for (std::uint32_t v = 0; v < mesh.vertex_count(2); ++v)
    {
        const BaseCoordinates& c = p.coordinates()[v];
        const Vec2d uv = atlas.uv(c.face, c.barycentric);
        const int x = std::min(atlas.size - 1, static_cast<int>(uv.x() * atlas.size));
        const int y = std::min(atlas.size - 1, static_cast<int>(uv.y() * atlas.size));
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * atlas.size + x);
        const Color expected = colour_at(mesh.world(v));
        worst = std::max({worst, std::abs(image.pixels[i] - double(expected.r)),
                          std::abs(image.pixels[i + 1] - double(expected.g)),
                          std::abs(image.pixels[i + 2] - double(expected.b))});
    }
    EXPECT_LT(worst, 16.0);
    PointCloud grey = samples;
    grey.colors.clear();
    EXPECT_THROW((void)bake_colors(mesh, p, atlas, 4, grey), InvalidInput);
}

TEST(Texture, TightAtlasesStillBakeEveryTriangle)
{
    // One colour baked into atlases from the smallest that the charts fit in up to a roomy
    // one: every sample must see it. Texels are baked wherever a chart touches them, not only
    // where their centres fall inside (a 128-texel atlas of 240 charts had left sub-triangles
    // without a texel, which bilinear look-ups read as black: RMS 18.9; here 63.8 at 16 texels
    // with gutters of 1).
    const MultiresMesh mesh = test::relief_sphere(3);
    const Parameterization p(mesh);
    PointCloud samples;
    for (std::size_t v = 0; v < mesh.vertex_count(3); ++v)
    {
        samples.positions.push_back(mesh.world(v).cast<float>());
        samples.colors.push_back(Color{200, 100, 50});
    }
    for (const int gutter : {1, 4})
    {
        int smallest = 0;
        for (int size = min_atlas_size; size <= 256; size *= 2)
        {
            Atlas atlas;
            try
            {
                atlas = make_atlas(mesh, 3, {.size = size, .gutter = gutter});
            }
            catch (const InvalidInput&)
            {
                continue; // the charts do not fit yet
            }
            if (smallest == 0)
                smallest = size;
            BakeReport report;
            (void)bake_colors(mesh, p, atlas, 3, samples, {}, &report);
            EXPECT_LT(report.rms_color_error, 1.0)
                << size << " texels a side, gutters of " << gutter;
        }
        EXPECT_GT(smallest, 0);
        EXPECT_LE(smallest, 64);
    }
}

TEST(Texture, NormalMapOfAFlatHierarchyIsStraightUpAndOfReliefIsNot)
{
    MultiresMesh flat(test::square_grid(4));
    for (int l = 0; l < 3; ++l)
        (void)flat.split();
    for (const bool relief : {false, true})
    {
        const MultiresMesh mesh = relief ? test::relief_plate(3) : flat;
        const Parameterization p(mesh);
        const Atlas atlas = make_atlas(mesh, 3, {.size = 256});
        const std::vector<std::size_t> level = {1};
        const TexturedMesh coarse = textured_levels(mesh, p, atlas, level);
        const TextureImage map = bake_normal_map(mesh, p, atlas, coarse, 3);
        double mean_blue = 0.0;
        double worst_tilt = 0.0;
        for (std::size_t i = 0; i < map.pixels.size(); i += 3)
        {
            mean_blue += map.pixels[i + 2];
            worst_tilt = std::max(
                {worst_tilt, std::abs(map.pixels[i] - 127.5), std::abs(map.pixels[i + 1] - 127.5)});
        }
        mean_blue /= static_cast<double>(map.pixels.size() / 3);
        if (!relief)
        {
            EXPECT_LE(worst_tilt, 1.0);
            EXPECT_GE(mean_blue, 254.0);
        }
        else
        {
            EXPECT_GT(worst_tilt, 10.0);
        }
        EXPECT_THROW((void)bake_normal_map(mesh, p, atlas, coarse, 1), InvalidInput);
    }
}

TEST(Texture, CheckerAndImage)
{
    const MultiresMesh mesh = test::relief_sphere(1);
    const Atlas atlas = make_atlas(mesh, 1, {.size = 128});
    const TextureImage checker = checker_texture(atlas, 8);
    ASSERT_EQ(checker.pixels.size(), 128U * 128U * 3U);
    EXPECT_NE(checker.pixels[0], checker.pixels[3 * 8]); // neighbouring squares differ
    TextureImage gradient;
    gradient.width = 2;
    gradient.height = 1;
    gradient.pixels = {0, 0, 0, 255, 255, 255};
    const TextureImage mapped = atlas_image(atlas, gradient);
    EXPECT_LT(mapped.pixels[0], mapped.pixels[3 * 127]); // left dark, right light
    EXPECT_THROW((void)atlas_image(atlas, TextureImage{}), InvalidInput);
}

TEST(Texture, SameBytesAtEveryThreadCount)
{
    const MultiresMesh mesh = test::relief_sphere(4);
    const Parameterization p(mesh);
    const Atlas atlas = make_atlas(mesh, 4, {.size = 512});
    PointCloud samples;
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        samples.positions.push_back(mesh.world(v).cast<float>());
        samples.colors.push_back(colour_at(mesh.world(v)));
    }
    const auto runs = test::at_thread_counts([&] {
        const TexturedMesh t = textured_levels(mesh, p, atlas, std::vector<std::size_t>{2, 4});
        return std::make_pair(bake_colors(mesh, p, atlas, 4, samples).pixels, t.uvs);
    });
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_TRUE(runs[i] == runs[0]) << "run " << i;
}

} // namespace
} // namespace pointform
