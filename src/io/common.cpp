// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "detail_readers.h"

#include <cctype>
#include <cmath>
#include <utility>

namespace pointform::detail {

std::string to_lower(std::string_view text)
{
    std::string out(text);
    for (char& c : out)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

NonFinitePolicy resolve_policy(NonFinitePolicy policy, FileFormat format)
{
    if (policy != NonFinitePolicy::FormatDefault)
        return policy;
    return format == FileFormat::Pcd ? NonFinitePolicy::Drop : NonFinitePolicy::Error;
}

CloudBuilder::CloudBuilder(const std::filesystem::path& path, NonFinitePolicy policy,
                           AttributeSet attributes, std::size_t expected)
    : path_(&path), policy_(policy), attributes_(attributes)
{
    cloud_.positions.reserve(expected);
    if (attributes_.normals)
        cloud_.normals.reserve(expected);
    if (attributes_.colors)
        cloud_.colors.reserve(expected);
    if (attributes_.radii)
        cloud_.radii.reserve(expected);
}

bool CloudBuilder::add(const PointRecord& point, Location where)
{
    if (!point.position.allFinite())
    {
        if (policy_ != NonFinitePolicy::Drop)
            fail(*path_,
                 "non-finite coordinate in point " + std::to_string(cloud_.size() + dropped_),
                 where);
        if (dropped_ == 0)
            first_dropped_ = where;
        ++dropped_;
        return false;
    }
    if (!has_origin_)
    {
        cloud_.origin = choose_origin(point.position);
        has_origin_ = true;
    }
    cloud_.positions.emplace_back((point.position - cloud_.origin).cast<float>());
    if (attributes_.normals)
        cloud_.normals.push_back(unit_or_zero(point.normal));
    if (attributes_.colors)
        cloud_.colors.push_back(point.color);
    if (attributes_.radii)
        cloud_.radii.push_back(point.radius);
    return true;
}

void CloudBuilder::check_no_drops_with_faces(bool has_faces) const
{
    if (has_faces && dropped_ > 0)
        fail(*path_,
             "cannot drop " + std::to_string(dropped_) +
                 " non-finite vertices from a file with faces (the face indices would be wrong)",
             first_dropped_);
}

PointCloud CloudBuilder::take()
{
    return std::exchange(cloud_, PointCloud{});
}

OutputBuffer::OutputBuffer(std::FILE* file, const std::filesystem::path& path)
    : file_(file), path_(&path)
{
    buffer_.reserve(capacity);
}

void OutputBuffer::flush()
{
    if (buffer_.empty())
        return;
    write_through(buffer_);
    buffer_.clear();
}

void OutputBuffer::write_through(std::string_view bytes)
{
    if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
        fail(*path_, "write failed (disk full or I/O error)");
}

void OutputBuffer::write_number(float value)
{
    char text[32];
    const auto result = std::to_chars(text, text + sizeof(text), value);
    write(std::string_view(text, static_cast<std::size_t>(result.ptr - text)));
}

void OutputBuffer::write_number(double value, int precision)
{
    constexpr int max_digits = 17; // enough for any double
    if (precision > max_digits)
        precision = max_digits;
    char text[64];
    const auto result = precision > 0 ? std::to_chars(text, text + sizeof(text), value,
                                                      std::chars_format::general, precision)
                                      : std::to_chars(text, text + sizeof(text), value);
    write(std::string_view(text, static_cast<std::size_t>(result.ptr - text)));
}

void OutputBuffer::write_integer(std::uint64_t value)
{
    char text[24];
    const auto result = std::to_chars(text, text + sizeof(text), value);
    write(std::string_view(text, static_cast<std::size_t>(result.ptr - text)));
}

void write_world_text(OutputBuffer& out, const PointCloudView& cloud, std::size_t i, int precision)
{
    const Vec3f& p = cloud.positions[i];
    const bool exact_float = precision <= 0 && cloud.origin.isZero(0.0);
    for (int axis = 0; axis < 3; ++axis)
    {
        if (axis > 0)
            out.put(' ');
        if (exact_float)
            out.write_number(p[axis]);
        else
            out.write_number(cloud.origin[axis] + static_cast<double>(p[axis]), precision);
    }
}

void write_triangle_text(OutputBuffer& out, const Triangle& t)
{
    out.write("3 ");
    out.write_integer(t[0]);
    out.put(' ');
    out.write_integer(t[1]);
    out.put(' ');
    out.write_integer(t[2]);
    out.put('\n');
}

} // namespace pointform::detail
