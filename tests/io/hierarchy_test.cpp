// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The hierarchy file: bit-exact round trips of refined hierarchies, the documented layout, and
// every kind of damaged file (truncated, another version, flipped bytes, hostile counts, wrong
// structure behind a valid checksum) rejected with a clear IoError.

#include "pointform/io/hierarchy.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/io.h"

#include "support/test_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

namespace pointform {
namespace {

/// An icosahedron of radius `radius` around `origin`, refined `levels` times by 1-to-4 splits
/// whose new vertices are pushed onto the sphere (as a refinement moves them onto f = 0).
MultiresMesh sphere_hierarchy(std::size_t levels, const Vec3d& origin, double radius)
{
    MultiresMesh mesh(test::icosphere(0, origin, radius));
    for (std::size_t l = 0; l < levels; ++l)
    {
        (void)mesh.split();
        for (Vec3d& p : mesh.finest_new_positions())
            p = radius * p.normalized();
    }
    return mesh;
}

/// A square grid (open, one boundary loop) refined `levels` times, lifted onto z = x·y.
MultiresMesh open_hierarchy(std::size_t levels)
{
    MultiresMesh mesh(test::square_grid(2));
    for (std::size_t l = 0; l < levels; ++l)
    {
        (void)mesh.split();
        for (Vec3d& p : mesh.finest_new_positions())
            p.z() = p.x() * p.y();
    }
    return mesh;
}

/// The smallest interesting file: a tetrahedron with one level of refinement (10 vertices).
MultiresMesh tiny_hierarchy()
{
    TriMesh tet;
    tet.vertices.positions = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
    tet.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
    MultiresMesh mesh(tet);
    (void)mesh.split();
    return mesh;
}

void expect_same_parts(const MultiresParts& a, const MultiresParts& b)
{
    EXPECT_EQ(std::memcmp(a.origin.data(), b.origin.data(), sizeof(double) * 3), 0);
    EXPECT_EQ(a.base_faces, b.base_faces);
    EXPECT_EQ(a.level_offsets, b.level_offsets);
    EXPECT_EQ(a.parent_edges, b.parent_edges);
    ASSERT_EQ(a.positions.size(), b.positions.size());
    // Bit for bit (memcmp also tells -0.0 from 0.0).
    EXPECT_EQ(
        std::memcmp(a.positions.data(), b.positions.data(), sizeof(Vec3d) * a.positions.size()), 0);
}

/// FNV-1a 64, written from the format's documentation (not the library's code).
std::uint64_t fnv1a(const std::string& bytes, std::size_t count)
{
    std::uint64_t h = 14695981039346656037ULL;
    for (std::size_t i = 0; i < count; ++i)
    {
        h ^= static_cast<unsigned char>(bytes[i]);
        h *= 1099511628211ULL;
    }
    return h;
}

template <typename T>
T get_le(const std::string& bytes, std::size_t offset)
{
    static_assert(std::endian::native == std::endian::little, "tests assume a little-endian host");
    T value;
    std::memcpy(&value, bytes.data() + offset, sizeof(T));
    return value;
}

template <typename T>
void put_le(std::string& bytes, std::size_t offset, T value)
{
    std::memcpy(bytes.data() + offset, &value, sizeof(T));
}

/// Recomputes the trailing checksum, so that a deliberate change reaches the structure checks.
void reseal(std::string& bytes)
{
    put_le(bytes, bytes.size() - 8, fnv1a(bytes, bytes.size() - 8));
}

/// Reading `path` throws an IoError that names the file and says `expected`.
void expect_read_error(const std::filesystem::path& path, const std::string& expected)
{
    try
    {
        (void)read_hierarchy(path);
        ADD_FAILURE() << "no error reading " << path << " (expected '" << expected << "')";
    }
    catch (const IoError& e)
    {
        const std::string message = e.what();
        EXPECT_NE(message.find(expected), std::string::npos) << message;
        EXPECT_NE(message.find(path.filename().string()), std::string::npos) << message;
    }
}

TEST(Hierarchy, SphereRoundTripIsBitExact)
{
    test::TempDir dir;
    const Vec3d origin(1.0e6, -2.5e5, 317.25); // georeferenced-like: the origin must survive
    MultiresMesh mesh = sphere_hierarchy(3, origin, 2.0);
    ASSERT_EQ(mesh.level_count(), 4U);
    const auto path = dir / "sphere.pfh";
    write_hierarchy(path, mesh);
    EXPECT_TRUE(is_hierarchy_file(path));

    const MultiresMesh read = read_hierarchy(path);
    expect_same_parts(mesh.parts(), read.parts());
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
        EXPECT_EQ(mesh.faces(level), read.faces(level)) << "level " << level;

    // The encoding is deterministic: writing what was read gives the same bytes.
    const auto again = dir / "again.pfh";
    write_hierarchy(again, read);
    EXPECT_EQ(test::read_file(path), test::read_file(again));
}

TEST(Hierarchy, FileSizeAndHeaderAreAsDocumented)
{
    test::TempDir dir;
    const MultiresMesh mesh = sphere_hierarchy(2, Vec3d(1, 2, 3), 1.0);
    const auto path = dir / "sphere.pfh";
    write_hierarchy(path, mesh);
    const std::string bytes = test::read_file(path);

    const std::size_t levels = mesh.level_count();
    const std::size_t vertices = mesh.vertex_count();
    const std::size_t faces = mesh.base_faces().size();
    const std::size_t parents = mesh.parent_edges().size();
    EXPECT_EQ(bytes.size(), 56 + 12 * faces + 4 * (levels + 1) + 8 * parents + 24 * vertices + 8);
    EXPECT_EQ(std::memcmp(bytes.data(), hierarchy_magic.data(), 8), 0);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 8), hierarchy_format_version);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 12), 0U);
    EXPECT_EQ(get_le<double>(bytes, 16), 1.0);
    EXPECT_EQ(get_le<double>(bytes, 24), 2.0);
    EXPECT_EQ(get_le<double>(bytes, 32), 3.0);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 40), levels);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 44), vertices);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 48), faces);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 52), parents);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 56 + 4), mesh.base_faces()[0][1]);
    const std::size_t offsets = 56 + 12 * faces;
    for (std::size_t i = 0; i <= levels; ++i)
        EXPECT_EQ(get_le<std::uint32_t>(bytes, offsets + 4 * i), mesh.level_offsets()[i]);
    const std::size_t edges = offsets + 4 * (levels + 1);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, edges + 8 * (parents - 1) + 4),
              mesh.parent_edges().back().b);
    const std::size_t positions = edges + 8 * parents;
    EXPECT_EQ(get_le<double>(bytes, positions + 24 * (vertices - 1) + 16),
              mesh.positions().back().z());
    EXPECT_EQ(get_le<std::uint64_t>(bytes, bytes.size() - 8), fnv1a(bytes, bytes.size() - 8));
}

TEST(Hierarchy, EveryLevelReadBackIsAClosedManifoldWithTheSplitCounts)
{
    test::TempDir dir;
    const double radius = 3.0;
    const auto path = dir / "sphere.pfh";
    write_hierarchy(path, sphere_hierarchy(3, Vec3d(-40.0, 12.0, 5.0), radius));
    const MultiresMesh mesh = read_hierarchy(path);

    std::size_t previous_vertices = 0;
    std::size_t previous_edges = 0;
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
    {
        const TriMesh m = mesh.level_mesh(level);
        const MeshTopology topo = analyze_topology(m);
        EXPECT_TRUE(topo.is_oriented_manifold()) << "level " << level;
        EXPECT_TRUE(topo.is_closed()) << "level " << level;
        EXPECT_EQ(topo.euler_characteristic, 2) << "level " << level;
        EXPECT_EQ(topo.components, 1U);
        EXPECT_EQ(m.face_count(), 20U << (2 * level));
        if (level > 0)
        {
            EXPECT_EQ(m.vertex_count(), previous_vertices + previous_edges) << "level " << level;
        }
        previous_vertices = m.vertex_count();
        previous_edges = topo.edges;
        // Every vertex is where the refinement put it: on the sphere.
        for (std::size_t v = 0; v < m.vertex_count(); ++v)
            ASSERT_NEAR((m.vertices.world(v) - mesh.origin()).norm(), radius, 1e-6 * radius);
    }
}

TEST(Hierarchy, OpenHierarchyRoundTrip)
{
    test::TempDir dir;
    MultiresMesh mesh = open_hierarchy(3);
    const std::size_t first_new = mesh.level_offsets()[mesh.finest_level()];
    mesh.finest_new_positions()[0].x() = -0.0; // a signed zero survives too
    const auto path = dir / "open.pfh";
    write_hierarchy(path, mesh);
    const MultiresMesh read = read_hierarchy(path);
    expect_same_parts(mesh.parts(), read.parts());
    EXPECT_TRUE(std::signbit(read.positions()[first_new].x()));
    for (std::size_t level = 0; level < read.level_count(); ++level)
    {
        const MeshTopology topo = analyze_topology(read.level_mesh(level));
        EXPECT_TRUE(topo.is_oriented_manifold());
        EXPECT_EQ(topo.boundary_loops, 1U);
        EXPECT_EQ(topo.euler_characteristic, 1);
    }
}

TEST(Hierarchy, BaseOnlyRoundTrip)
{
    test::TempDir dir;
    const MultiresMesh mesh(test::icosphere(0));
    const auto path = dir / "base.pfh";
    write_hierarchy(path, mesh);
    const MultiresMesh read = read_hierarchy(path);
    expect_same_parts(mesh.parts(), read.parts());
    EXPECT_EQ(read.level_count(), 1U);
}

TEST(Hierarchy, EveryTruncationIsRejected)
{
    test::TempDir dir;
    const auto full = dir / "tiny.pfh";
    write_hierarchy(full, tiny_hierarchy());
    const std::string bytes = test::read_file(full);
    ASSERT_EQ(bytes.size(), 56U + 12 * 4 + 4 * 3 + 8 * 6 + 24 * 10 + 8);
    const auto cut = dir / "cut.pfh";
    for (std::size_t n = 0; n < bytes.size(); ++n)
    {
        SCOPED_TRACE("length " + std::to_string(n));
        test::write_file(cut, bytes.substr(0, n));
        expect_read_error(cut, n == 0 ? "file is empty" : "truncated");
    }
}

TEST(Hierarchy, EveryFlippedByteIsRejected)
{
    test::TempDir dir;
    const auto full = dir / "tiny.pfh";
    write_hierarchy(full, tiny_hierarchy());
    const std::string bytes = test::read_file(full);
    const auto flipped = dir / "flipped.pfh";
    for (std::size_t i = 0; i < bytes.size(); ++i)
    {
        SCOPED_TRACE("byte " + std::to_string(i));
        std::string copy = bytes;
        copy[i] = static_cast<char>(copy[i] ^ 0x10);
        test::write_file(flipped, copy);
        if (i < 8)
            expect_read_error(flipped, "not a pointform hierarchy");
        else if (i < 12)
            expect_read_error(flipped, "version");
        else if (i >= 16 && (i < 40 || i >= 56))
            expect_read_error(flipped, "corrupt hierarchy: checksum mismatch");
        else
            EXPECT_THROW((void)read_hierarchy(flipped), IoError); // flags or a count
    }
}

TEST(Hierarchy, OtherVersionsNameBothVersions)
{
    test::TempDir dir;
    const auto path = dir / "v.pfh";
    write_hierarchy(path, tiny_hierarchy());
    for (const std::uint32_t version : {0U, 3U, 77U})
    {
        std::string bytes = test::read_file(path);
        put_le(bytes, 8, version);
        reseal(bytes);
        const auto other = dir / ("v" + std::to_string(version) + ".pfh");
        test::write_file(other, bytes);
        EXPECT_TRUE(is_hierarchy_file(other));
        expect_read_error(other, "format version " + std::to_string(version) +
                                     " is not supported (this build reads versions 1 and 2)");
    }
}

TEST(Hierarchy, HugeCountsAreRejectedBeforeAllocating)
{
    test::TempDir dir;
    const auto path = dir / "tiny.pfh";
    write_hierarchy(path, tiny_hierarchy());
    // Levels, vertices, base faces, parent edges: each at its maximum (about 100 GB announced
    // for the vertices), with a valid checksum; the size check must answer first.
    for (const std::size_t field : {40U, 44U, 48U, 52U})
    {
        std::string bytes = test::read_file(path);
        put_le(bytes, field, std::numeric_limits<std::uint32_t>::max());
        reseal(bytes);
        const auto huge = dir / ("huge" + std::to_string(field) + ".pfh");
        test::write_file(huge, bytes);
        expect_read_error(huge, "truncated");
    }
    // All counts zero: the file is far longer than announced.
    std::string bytes = test::read_file(path);
    for (const std::size_t field : {40U, 44U, 48U, 52U})
        put_le(bytes, field, std::uint32_t{0});
    const auto zero = dir / "zero.pfh";
    test::write_file(zero, bytes);
    expect_read_error(zero, "bytes after the end of the data");
}

TEST(Hierarchy, WrongStructureBehindAValidChecksumIsRejected)
{
    test::TempDir dir;
    const auto path = dir / "tiny.pfh";
    write_hierarchy(path, tiny_hierarchy());
    const std::string good = test::read_file(path);
    const std::size_t faces = 56;
    const std::size_t offsets = faces + 12 * 4;
    const std::size_t parents = offsets + 4 * 3;
    const std::size_t positions = parents + 8 * 6;
    const auto bad = dir / "bad.pfh";
    const auto check = [&](std::string bytes, const std::string& expected) {
        reseal(bytes);
        test::write_file(bad, bytes);
        expect_read_error(bad, "invalid hierarchy");
        expect_read_error(bad, expected);
    };
    {
        std::string bytes = good; // a base face pointing past the base vertices
        put_le(bytes, faces + 4, std::uint32_t{7});
        check(bytes, "references vertex 7");
    }
    {
        std::string bytes = good; // two new vertices on the same edge
        put_le(bytes, parents + 8, get_le<std::uint32_t>(bytes, parents));
        put_le(bytes, parents + 12, get_le<std::uint32_t>(bytes, parents + 4));
        check(bytes, "split the same edge");
    }
    {
        std::string bytes = good; // a parent edge end beyond level 0
        put_le(bytes, parents, std::uint32_t{9});
        check(bytes, "outside level 0");
    }
    {
        std::string bytes = good; // level offsets that do not start at 0
        put_le(bytes, offsets, std::uint32_t{1});
        check(bytes, "first level offset must be 0");
    }
    {
        std::string bytes = good; // a position that is not finite
        put_le(bytes, positions + 24 * 5 + 8, std::numeric_limits<double>::quiet_NaN());
        check(bytes, "position of vertex 5 is not finite");
    }
}

TEST(Hierarchy, MissingDirectoryAndForeignFiles)
{
    test::TempDir dir;
    expect_read_error(dir / "nowhere.pfh", "does not exist");
    expect_read_error(dir.path(), "is a directory");
    EXPECT_FALSE(is_hierarchy_file(dir / "nowhere.pfh"));
    EXPECT_FALSE(is_hierarchy_file(dir.path()));

    const auto ply = dir / "mesh.ply";
    write_mesh(ply, test::icosphere(1));
    EXPECT_FALSE(is_hierarchy_file(ply));
    expect_read_error(ply, "not a pointform hierarchy");
    const auto text = dir / "notes.pfh";
    test::write_file(text, "just some text that is long enough to have a header\n");
    expect_read_error(text, "not a pointform hierarchy");
}

TEST(Hierarchy, WritingFailsCleanly)
{
    test::TempDir dir;
    EXPECT_THROW(write_hierarchy(dir / "x.pfh", MultiresMesh()), InvalidInput);
    EXPECT_THROW(write_hierarchy(dir / "no" / "such" / "dir.pfh", tiny_hierarchy()), IoError);
    // Overwriting goes through a temporary file: afterwards only the new file is there.
    const auto path = dir / "h.pfh";
    write_hierarchy(path, tiny_hierarchy());
    const MultiresMesh bigger = sphere_hierarchy(1, Vec3d::Zero(), 1.0);
    write_hierarchy(path, bigger);
    expect_same_parts(bigger.parts(), read_hierarchy(path).parts());
    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
        ++entries;
    EXPECT_EQ(entries, 1U);
}

TEST(Hierarchy, RecordsThePredictorAndReadsVersionOneAsMidpoint)
{
    test::TempDir dir;
    const auto path = dir / "p.pfh";
    MultiresMesh mesh = tiny_hierarchy();
    mesh.set_predictor(Predictor::Butterfly);
    write_hierarchy(path, mesh);
    EXPECT_EQ(read_hierarchy(path).predictor(), Predictor::Butterfly);

    std::string bytes = test::read_file(path);
    EXPECT_EQ(get_le<std::uint32_t>(bytes, 12), 1U);
    put_le(bytes, 12, 7U);
    reseal(bytes);
    const auto unknown = dir / "unknown.pfh";
    test::write_file(unknown, bytes);
    expect_read_error(unknown, "unknown predictor 7");

    // Version 1: the word at offset 12 is flags (0), and the hierarchy reads as midpoint.
    put_le(bytes, 8, 1U);
    put_le(bytes, 12, 0U);
    reseal(bytes);
    const auto v1 = dir / "v1.pfh";
    test::write_file(v1, bytes);
    const MultiresMesh old = read_hierarchy(v1);
    EXPECT_EQ(hierarchy_file_version(v1), 1U);
    EXPECT_EQ(hierarchy_file_version(path), hierarchy_format_version);
    EXPECT_EQ(hierarchy_file_version(dir / "missing.pfh"), std::nullopt);
    test::write_file(dir / "short.pfh", bytes.substr(0, 10));
    EXPECT_EQ(hierarchy_file_version(dir / "short.pfh"), std::nullopt);
    EXPECT_EQ(old.predictor(), Predictor::Midpoint);
    EXPECT_EQ(old.vertex_count(), mesh.vertex_count());
    put_le(bytes, 12, 1U);
    reseal(bytes);
    test::write_file(v1, bytes);
    expect_read_error(v1, "unknown flags");
}

} // namespace
} // namespace pointform
