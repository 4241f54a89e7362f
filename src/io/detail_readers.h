// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

// Private to src/io: the per-format readers and writers, and the helpers they share (a byte
// cursor that tracks its offset, endian conversion, a line reader that counts lines, number
// parsing, a point-cloud builder that applies the origin and the non-finite policy, and a
// buffered output sink).

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/io/io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace pointform::detail {

/// \brief A file's bytes, read by read_whole_file().
class FileBytes
{
public:
    explicit FileBytes(std::size_t size)
        : bytes_(std::make_unique_for_overwrite<char[]>(size)), size_(size)
    {}

    [[nodiscard]] char* data() { return bytes_.get(); }
    [[nodiscard]] const char* data() const { return bytes_.get(); }
    [[nodiscard]] std::size_t size() const { return size_; }
    // NOLINTNEXTLINE(google-explicit-constructor): read as a string_view everywhere
    operator std::string_view() const { return {bytes_.get(), size_}; }

private:
    std::unique_ptr<char[]> bytes_;
    std::size_t size_;
};

/// \brief The whole file as bytes (large files read in parallel pieces, into memory that is not
/// cleared first), as long as it was when read began. \throw IoError naming the file if it is
/// missing, a directory, empty or unreadable, or shorter by the time it is read
[[nodiscard]] FileBytes read_whole_file(const std::filesystem::path& path);

/// Where in a file a problem was found: a 1-based line (text) or a byte offset (binary).
struct Location
{
    std::optional<std::uint64_t> line;
    std::optional<std::uint64_t> offset;

    static Location at_line(std::uint64_t line) { return {line, std::nullopt}; }
    static Location at_byte(std::uint64_t offset) { return {std::nullopt, offset}; }
};

[[noreturn]] inline void fail(const std::filesystem::path& path, const std::string& what,
                              Location where = {})
{
    throw IoError(path, what, where.line, where.offset);
}

enum class ByteOrder
{
    Little,
    Big,
};

constexpr ByteOrder native_byte_order =
    std::endian::native == std::endian::little ? ByteOrder::Little : ByteOrder::Big;

template <typename T>
[[nodiscard]] T byte_swap(T value)
{
    static_assert(std::is_trivially_copyable_v<T>);
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i)
    {
        const unsigned char tmp = bytes[i];
        bytes[i] = bytes[sizeof(T) - 1 - i];
        bytes[sizeof(T) - 1 - i] = tmp;
    }
    std::memcpy(&value, bytes, sizeof(T));
    return value;
}

/// Loads a T stored in `order` at `p` (no alignment needed).
template <typename T>
[[nodiscard]] T load(const char* p, ByteOrder order)
{
    T value;
    std::memcpy(&value, p, sizeof(T));
    return order == native_byte_order ? value : byte_swap(value);
}

/// A read position over a file's bytes that knows its offset, so that every error can name it.
class ByteCursor
{
public:
    ByteCursor(const std::filesystem::path& path, std::string_view bytes, std::size_t offset = 0)
        : path_(&path), bytes_(bytes), offset_(offset)
    {}

    [[nodiscard]] std::size_t offset() const { return offset_; }
    /// Bytes after the offset; 0 once a seek() has gone past the end.
    [[nodiscard]] std::size_t remaining() const
    {
        return offset_ <= bytes_.size() ? bytes_.size() - offset_ : 0;
    }
    [[nodiscard]] const char* data() const { return bytes_.data() + offset_; }
    [[nodiscard]] const std::filesystem::path& path() const { return *path_; }

    /// Throws a "truncated" IoError at the current offset unless `n` more bytes are available.
    void require(std::uint64_t n, std::string_view what) const
    {
        if (n > remaining())
            fail(*path_,
                 "file is truncated: " + std::string(what) + " needs " + std::to_string(n) +
                     " bytes but only " + std::to_string(remaining()) + " remain",
                 Location::at_byte(offset_));
    }

    template <typename T>
    [[nodiscard]] T read(ByteOrder order, std::string_view what)
    {
        require(sizeof(T), what);
        const T value = load<T>(data(), order);
        offset_ += sizeof(T);
        return value;
    }

    template <typename T>
    [[nodiscard]] T read_le(std::string_view what)
    {
        return read<T>(ByteOrder::Little, what);
    }

    void skip(std::uint64_t n, std::string_view what)
    {
        require(n, what);
        offset_ += static_cast<std::size_t>(n);
    }

    /// Moves to `offset`, which may lie past the end: the next require() then fails as truncated.
    void seek(std::size_t offset) { offset_ = offset; }

private:
    const std::filesystem::path* path_;
    std::string_view bytes_;
    std::size_t offset_;
};

/// Splits text into lines (without '\n' or a trailing '\r') and counts them from 1.
class LineReader
{
public:
    explicit LineReader(std::string_view text, std::size_t start = 0,
                        std::uint64_t lines_before = 0)
        : text_(text), pos_(start), line_(lines_before)
    {}

    /// Next line, or false at the end of the text.
    bool next(std::string_view& line)
    {
        if (pos_ >= text_.size())
            return false;
        const std::size_t end = text_.find('\n', pos_);
        const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
        line = text_.substr(pos_, stop - pos_);
        if (!line.empty() && line.back() == '\r')
            line.remove_suffix(1);
        pos_ = end == std::string_view::npos ? text_.size() : end + 1;
        ++line_;
        return true;
    }

    /// 1-based number of the line last returned (0 before the first).
    [[nodiscard]] std::uint64_t line_number() const { return line_; }
    /// Byte offset just past the line last returned.
    [[nodiscard]] std::size_t offset() const { return pos_; }
    [[nodiscard]] std::size_t remaining() const { return text_.size() - pos_; }

private:
    std::string_view text_;
    std::size_t pos_;
    std::uint64_t line_;
};

[[nodiscard]] constexpr bool is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == '\n';
}

/// Takes the next token off `rest`. Separators are white space, plus ',' if `commas`.
/// Returns false when no token is left.
inline bool next_token(std::string_view& rest, std::string_view& token, bool commas = false)
{
    std::size_t i = 0;
    const std::size_t n = rest.size();
    while (i < n && (is_space(rest[i]) || (commas && rest[i] == ',')))
        ++i;
    if (i == n)
    {
        rest = {};
        return false;
    }
    std::size_t j = i;
    while (j < n && !is_space(rest[j]) && !(commas && rest[j] == ','))
        ++j;
    token = rest.substr(i, j - i);
    rest.remove_prefix(j);
    return true;
}

/// Text with leading and trailing white space removed.
[[nodiscard]] inline std::string_view trim(std::string_view text)
{
    while (!text.empty() && is_space(text.front()))
        text.remove_prefix(1);
    while (!text.empty() && is_space(text.back()))
        text.remove_suffix(1);
    return text;
}

/// Parses a whole token with std::from_chars as a T (an integer type or double), also accepting
/// a leading '+'. The whole token must be consumed.
template <typename T>
[[nodiscard]] bool parse_whole_token(std::string_view token, T& value)
{
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (first != last && *first == '+')
        ++first;
    const auto [ptr, ec] = std::from_chars(first, last, value);
    return ec == std::errc() && ptr == last && first != last;
}

/// Parses a whole token as a double (accepts a leading '+', "nan" and "inf").
[[nodiscard]] inline bool parse_double(std::string_view token, double& value)
{
    return parse_whole_token(token, value);
}

/// Parses a whole token as an integer of type T (accepts a leading '+' for signed and unsigned).
template <typename T>
[[nodiscard]] bool parse_integer(std::string_view token, T& value)
{
    static_assert(std::is_integral_v<T>);
    return parse_whole_token(token, value);
}

/// Short, printable excerpt of a token for error messages.
[[nodiscard]] inline std::string quote(std::string_view token)
{
    constexpr std::size_t max_length = 40;
    std::string out = "'";
    for (const char c : token.substr(0, max_length))
        out += (c >= 32 && c < 127) ? c : '?';
    if (token.size() > max_length)
        out += "...";
    out += "'";
    return out;
}

/// Lower-case ASCII copy.
[[nodiscard]] std::string to_lower(std::string_view text);

/// Which optional attributes a reader fills.
struct AttributeSet
{
    bool normals = false;
    bool colors = false;
    bool radii = false;
};

/// One point as a reader sees it, in world coordinates.
struct PointRecord
{
    Vec3d position = Vec3d::Zero();
    Vec3f normal = Vec3f::Zero();
    Color color;
    float radius = 0.0F;
};

/// What a value read from a file means for its point: the one vocabulary of every reader (PLY
/// vertex properties, text columns, PCD fields).
enum class Field : std::uint8_t
{
    None, ///< not stored (a property or column we do not use)
    X,
    Y,
    Z,
    Nx,
    Ny,
    Nz,
    Red,
    Green,
    Blue,
    Radius,
};
constexpr std::size_t field_count = static_cast<std::size_t>(Field::Radius) + 1;

[[nodiscard]] constexpr bool is_color(Field field)
{
    return field == Field::Red || field == Field::Green || field == Field::Blue;
}

/// One name a format gives a field.
struct FieldName
{
    std::string_view name;
    Field field;
};

/// The field that `vocabulary` (a format's field names) gives `name`, or Field::None.
[[nodiscard]] constexpr Field field_named(std::string_view name,
                                          std::span<const FieldName> vocabulary)
{
    for (const FieldName& entry : vocabulary)
        if (entry.name == name)
            return entry.field;
    return Field::None;
}

/// Stores `value` into `point` as `field` says: positions as double, normal components and the
/// radius as float. A color channel must already be in [0, 255]: each format encodes colors its
/// own way, so the reader converts them (see is_color) before this call.
inline void set_field(PointRecord& point, Field field, double value)
{
    switch (field)
    {
        case Field::X:
            point.position.x() = value;
            break;
        case Field::Y:
            point.position.y() = value;
            break;
        case Field::Z:
            point.position.z() = value;
            break;
        case Field::Nx:
            point.normal.x() = static_cast<float>(value);
            break;
        case Field::Ny:
            point.normal.y() = static_cast<float>(value);
            break;
        case Field::Nz:
            point.normal.z() = static_cast<float>(value);
            break;
        case Field::Red:
            point.color.r = static_cast<std::uint8_t>(value);
            break;
        case Field::Green:
            point.color.g = static_cast<std::uint8_t>(value);
            break;
        case Field::Blue:
            point.color.b = static_cast<std::uint8_t>(value);
            break;
        case Field::Radius:
            point.radius = static_cast<float>(value);
            break;
        case Field::None:
            break;
    }
}

/// The fields a file declares, and what they add up to.
class FieldSet
{
public:
    void add(Field field) { found_[static_cast<std::size_t>(field)] = true; }
    [[nodiscard]] bool has(Field field) const { return found_[static_cast<std::size_t>(field)]; }
    [[nodiscard]] bool has_position() const
    {
        return has(Field::X) && has(Field::Y) && has(Field::Z);
    }
    /// Normals need nx, ny and nz; colors red, green and blue; radii a radius.
    [[nodiscard]] AttributeSet attributes() const
    {
        AttributeSet attributes;
        attributes.normals = has(Field::Nx) && has(Field::Ny) && has(Field::Nz);
        attributes.colors = has(Field::Red) && has(Field::Green) && has(Field::Blue);
        attributes.radii = has(Field::Radius);
        return attributes;
    }

private:
    std::array<bool, field_count> found_{};
};

/// Resolves NonFinitePolicy::FormatDefault: Drop for PCD, Error for everything else.
[[nodiscard]] NonFinitePolicy resolve_policy(NonFinitePolicy policy, FileFormat format);

/// Collects points into a PointCloud: chooses the origin from the first kept point, stores
/// positions as float relative to it, normalizes normals, and applies the non-finite policy.
/// Points a block of CloudBuilder::add_all().
inline constexpr std::size_t add_all_block = std::size_t{1} << 16U;
/// No point, in CloudBuilder::add_all().
inline constexpr std::size_t add_all_none = ~std::size_t{0};

/// A file's normal scaled to unit length; zero where it has no length (or none that is finite).
[[nodiscard]] inline Vec3f unit_or_zero(const Vec3f& normal)
{
    const float length = normal.norm();
    return std::isfinite(length) && length > 0.0F ? Vec3f(normal / length) : Vec3f::Zero();
}

class CloudBuilder
{
public:
    /// \param expected  number of points announced by the header (already capped by file size)
    CloudBuilder(const std::filesystem::path& path, NonFinitePolicy policy, AttributeSet attributes,
                 std::size_t expected);

    /// Adds a point. Returns false if it was dropped (non-finite coordinates under Drop).
    /// Throws IoError at `where` for non-finite coordinates under Error.
    bool add(const PointRecord& point, Location where);

    /// Adds points 0 to count - 1, which `decode(i, point)` fills in (from any thread; it must
    /// not depend on the order of calls), as add() called on each in turn would: the same cloud,
    /// the same drops, the same error. `position_of(i)` is point i's position alone (read
    /// first, to place the points). Decodes in parallel.
    template <typename PositionOf, typename Decode, typename WhereOf>
    void add_all(std::size_t count, const PositionOf& position_of, const Decode& decode,
                 const WhereOf& where_of);

    [[nodiscard]] std::size_t dropped() const { return dropped_; }

    /// Throws if points were dropped from a file that has faces (the indices would be wrong).
    void check_no_drops_with_faces(bool has_faces) const;

    /// Hands the cloud over; the builder is empty afterwards.
    [[nodiscard]] PointCloud take();

private:
    const std::filesystem::path* path_;
    NonFinitePolicy policy_;
    AttributeSet attributes_;
    PointCloud cloud_;
    bool has_origin_ = false;
    std::size_t dropped_ = 0;
    Location first_dropped_;
};

template <typename PositionOf, typename Decode, typename WhereOf>
void CloudBuilder::add_all(std::size_t count, const PositionOf& position_of, const Decode& decode,
                           const WhereOf& where_of)
{
    const std::size_t block = add_all_block;
    const std::size_t blocks = (count + block - 1) / block;
    // 1. Each block's non-finite points: how many, and the first; and its first finite point.
    struct Tally
    {
        std::size_t bad = 0;
        std::size_t first_bad = add_all_none;
        std::size_t first_good = add_all_none;
    };
    std::vector<Tally> tally(blocks);
    parallel_blocks(blocks, 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t b = first; b < last; ++b)
            for (std::size_t i = b * block; i < std::min(count, (b + 1) * block); ++i)
            {
                Tally& t = tally[b];
                if (position_of(i).allFinite())
                {
                    if (t.first_good == add_all_none)
                        t.first_good = i;
                }
                else if (t.bad++ == 0)
                    t.first_bad = i;
            }
    });
    std::size_t bad = 0;
    std::size_t first_bad = add_all_none;
    std::size_t first_good = add_all_none;
    std::vector<std::size_t> good_before(blocks + 1, 0);
    for (std::size_t b = 0; b < blocks; ++b)
    {
        if (first_bad == add_all_none)
            first_bad = tally[b].first_bad;
        if (first_good == add_all_none)
            first_good = tally[b].first_good;
        bad += tally[b].bad;
        const std::size_t size = std::min(count, (b + 1) * block) - b * block;
        good_before[b + 1] = good_before[b] + size - tally[b].bad;
    }
    if (bad > 0)
    {
        if (policy_ != NonFinitePolicy::Drop)
            fail(*path_,
                 "non-finite coordinate in point " +
                     std::to_string(cloud_.size() + dropped_ + first_bad),
                 where_of(first_bad));
        if (dropped_ == 0)
            first_dropped_ = where_of(first_bad);
        dropped_ += bad;
    }
    if (first_good == add_all_none)
        return;
    if (!has_origin_)
    {
        cloud_.origin = choose_origin(position_of(first_good));
        has_origin_ = true;
    }
    // 2. Every finite point in its place, after the points added before.
    const std::size_t start = cloud_.size();
    const std::size_t total = start + good_before[blocks];
    cloud_.positions.resize(total);
    if (attributes_.normals)
        cloud_.normals.resize(total);
    if (attributes_.colors)
        cloud_.colors.resize(total);
    if (attributes_.radii)
        cloud_.radii.resize(total);
    parallel_blocks(blocks, 1, [&](std::size_t first, std::size_t last) {
        PointRecord record;
        for (std::size_t b = first; b < last; ++b)
        {
            std::size_t at = start + good_before[b];
            for (std::size_t i = b * block; i < std::min(count, (b + 1) * block); ++i)
            {
                decode(i, record);
                if (!record.position.allFinite())
                    continue;
                cloud_.positions[at] = (record.position - cloud_.origin).cast<float>();
                if (attributes_.normals)
                    cloud_.normals[at] = unit_or_zero(record.normal);
                if (attributes_.colors)
                    cloud_.colors[at] = record.color;
                if (attributes_.radii)
                    cloud_.radii[at] = record.radius;
                ++at;
            }
        }
    });
}

/// How many elements to reserve when a header announces `declared` items of at least
/// `min_bytes` each and `available` bytes remain: never more than the file can hold.
[[nodiscard]] constexpr std::size_t capped_reserve(std::uint64_t declared, std::uint64_t available,
                                                   std::uint64_t min_bytes)
{
    const std::uint64_t fit = available / (min_bytes == 0 ? 1 : min_bytes);
    return static_cast<std::size_t>(declared < fit ? declared : fit);
}

/// Fan-triangulates a polygon given by its vertex indices (fewer than 3 adds nothing).
inline void append_fan(std::vector<Triangle>& triangles, std::span<const std::uint32_t> polygon)
{
    for (std::size_t k = 2; k < polygon.size(); ++k)
        triangles.push_back({polygon[0], polygon[k - 1], polygon[k]});
}

/// Buffered writer over a FILE*; throws IoError naming the file when a write fails.
class OutputBuffer
{
public:
    OutputBuffer(std::FILE* file, const std::filesystem::path& path);
    OutputBuffer(const OutputBuffer&) = delete;
    OutputBuffer& operator=(const OutputBuffer&) = delete;
    ~OutputBuffer() = default;

    void write(std::string_view bytes)
    {
        if (buffer_.size() + bytes.size() > capacity)
            flush();
        if (bytes.size() >= capacity)
            write_through(bytes);
        else
            buffer_.append(bytes);
    }

    void put(char c)
    {
        if (buffer_.size() + 1 > capacity)
            flush();
        buffer_.push_back(c);
    }

    /// Writes the bytes of `value` little-endian.
    template <typename T>
    void write_le(T value)
    {
        if constexpr (native_byte_order != ByteOrder::Little)
            value = byte_swap(value);
        char bytes[sizeof(T)];
        std::memcpy(bytes, &value, sizeof(T));
        write(std::string_view(bytes, sizeof(T)));
    }

    /// Shortest text that reads back as the same float.
    void write_number(float value);
    /// Shortest round-trip text of a double, or `precision` significant digits if > 0.
    void write_number(double value, int precision);
    void write_integer(std::uint64_t value);

    /// Writes out everything buffered. Throws IoError on failure.
    void flush();

    /// Encodes items 0 to count - 1 of `size` bytes each, `encode(i, p)` writing item i at p
    /// (from any thread), in parallel, a few hundred thousand at a time.
    template <typename Encode>
    void write_items(std::size_t count, std::size_t size, const Encode& encode)
    {
        constexpr std::size_t round = std::size_t{1} << 18U;
        std::vector<char> bytes;
        for (std::size_t first = 0; first < count; first += round)
        {
            const std::size_t items = std::min(round, count - first);
            bytes.resize(items * size);
            parallel_blocks(items, 8192, [&](std::size_t begin, std::size_t end) {
                for (std::size_t i = begin; i < end; ++i)
                    encode(first + i, bytes.data() + i * size);
            });
            write(std::string_view(bytes.data(), bytes.size()));
        }
    }

private:
    /// Writes `bytes` to the file, past the buffer (which must be flushed first).
    void write_through(std::string_view bytes);

    static constexpr std::size_t capacity = std::size_t{1} << 20;

    std::FILE* file_;
    const std::filesystem::path* path_;
    std::string buffer_;
};

/// Writes the world position of point i as "x y z" text: float shortest when the origin is zero
/// and no precision is asked, else the double world value.
void write_world_text(OutputBuffer& out, const PointCloudView& cloud, std::size_t i, int precision);

/// Writes a triangle as the text face line "3 a b c" (OFF and ascii PLY).
void write_triangle_text(OutputBuffer& out, const Triangle& t);

[[nodiscard]] ReadResult read_ply(const std::filesystem::path& path, std::string_view bytes,
                                  NonFinitePolicy policy);
/// \param pts_hint  the file name ends in .pts (a 7-column file is x y z intensity r g b)
[[nodiscard]] ReadResult read_text(const std::filesystem::path& path, std::string_view bytes,
                                   NonFinitePolicy policy, bool pts_hint);
[[nodiscard]] ReadResult read_off(const std::filesystem::path& path, std::string_view bytes,
                                  NonFinitePolicy policy);
[[nodiscard]] ReadResult read_obj(const std::filesystem::path& path, std::string_view bytes,
                                  NonFinitePolicy policy);
[[nodiscard]] ReadResult read_pcd(const std::filesystem::path& path, std::string_view bytes,
                                  NonFinitePolicy policy);
[[nodiscard]] ReadResult read_las(const std::filesystem::path& path, std::string_view bytes,
                                  NonFinitePolicy policy);

/// Decompresses an LZF stream into exactly `output.size()` bytes. Returns false if the stream
/// is malformed, refers outside the output, or does not fill the output exactly.
[[nodiscard]] bool lzf_decompress(std::string_view input, std::span<char> output);

void write_ply(OutputBuffer& out, const PointCloudView& cloud, std::span<const Triangle> triangles,
               bool ascii, int precision);
void write_xyz(OutputBuffer& out, const PointCloudView& cloud, int precision);
void write_off(OutputBuffer& out, const TriMesh& mesh, int precision);
void write_obj(OutputBuffer& out, const TriMesh& mesh, int precision);

} // namespace pointform::detail
