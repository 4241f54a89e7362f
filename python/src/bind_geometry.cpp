// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"

#include "common.h"

#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>

namespace pointform::python {
namespace {

std::string shape_text(const py::array& a)
{
    std::ostringstream out;
    out << '(';
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
        out << (i > 0 ? ", " : "") << a.shape(i);
    out << (a.ndim() == 1 ? ",)" : ")");
    return out.str();
}

std::string dtype_text(const py::array& a)
{
    return py::str(a.dtype()).cast<std::string>();
}

char dtype_kind(const py::array& a)
{
    return a.dtype().kind();
}

bool is_native(const py::array& a, const py::dtype& dtype)
{
    return a.dtype().equal(dtype);
}

std::string row_text(double x, double y, double z)
{
    std::ostringstream out;
    out.precision(std::numeric_limits<double>::max_digits10);
    out << '(' << x << ", " << y << ", " << z << ')';
    return out.str();
}

/// Checks an N by 3 real array: its shape, dtype, row count.
void check_rows3(const py::array& a, const char* name, std::optional<std::size_t> rows,
                 bool allow_empty)
{
    const char kind = dtype_kind(a);
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw InvalidInput(std::string(name) + ": expected real numbers, got dtype " +
                           dtype_text(a));
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw InvalidInput(std::string(name) + ": expected an N by 3 array, got shape " +
                           shape_text(a));
    const auto n = static_cast<std::size_t>(a.shape(0));
    if (n == 0 && !allow_empty)
        throw InvalidInput(std::string(name) + ": the array is empty (0 rows)");
    if (rows && n != *rows)
        throw InvalidInput(std::string(name) + ": expected " + std::to_string(*rows) +
                           " rows (one per point), got " + std::to_string(n));
}

/// Reads a strided real array (float or double storage) row by row into `out`.
template <class Scalar, class Out>
void read_rows(const py::array& a, const char* name, const Vec3d& origin, Out* out,
               py::ssize_t n = -1)
{
    const auto* base = static_cast<const char*>(a.data());
    const py::ssize_t s0 = a.strides(0);
    const py::ssize_t s1 = a.strides(1);
    if (n < 0)
        n = a.shape(0);
    for (py::ssize_t i = 0; i < n; ++i)
    {
        double v[3];
        for (int j = 0; j < 3; ++j)
        {
            Scalar s;
            std::memcpy(&s, base + i * s0 + j * s1, sizeof(Scalar));
            v[j] = static_cast<double>(s);
        }
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
            throw InvalidInput(std::string(name) + "[" + std::to_string(i) +
                               "] is not finite: " + row_text(v[0], v[1], v[2]));
        using T = typename Out::Scalar;
        const Out row(static_cast<T>(v[0] - origin.x()), static_cast<T>(v[1] - origin.y()),
                      static_cast<T>(v[2] - origin.z()));
        if (!row.allFinite())
            throw InvalidInput(std::string(name) + "[" + std::to_string(i) +
                               "] = " + row_text(v[0], v[1], v[2]) +
                               " is out of the float32 range relative to the origin");
        out[i] = row;
    }
}

/// A real array that is not float32 or float64 in native order, as float64 (numpy converts it).
py::array as_float64(const py::array& a)
{
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
}

/// Whether `a` holds T exactly as the library stores it: native dtype, C order, aligned.
template <class T>
bool in_library_layout(const py::array& a)
{
    return is_native(a, py::dtype::of<T>()) && (a.flags() & py::array::c_style) != 0 &&
           (a.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) != 0;
}

void check_finite_rows(std::span<const Vec3f> rows, const char* name)
{
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (!rows[i].allFinite())
            throw InvalidInput(std::string(name) + "[" + std::to_string(i) + "] is not finite: " +
                               row_text(rows[i].x(), rows[i].y(), rows[i].z()));
}

} // namespace

py::array as_array(const py::handle& object, const char* name)
{
    py::array a = py::array::ensure(object);
    if (!a)
    {
        PyErr_Clear();
        throw InvalidInput(std::string(name) +
                           ": expected a numpy array (or a nested sequence "
                           "of numbers)");
    }
    return a;
}

std::vector<Vec3f> vec3f_rows(const py::handle& array, const char* name,
                              std::optional<std::size_t> rows, const Vec3d& origin,
                              bool allow_empty)
{
    py::array a = as_array(array, name);
    check_rows3(a, name, rows, allow_empty);
    const auto n = static_cast<std::size_t>(a.shape(0));
    std::vector<Vec3f> out(n);
    if (n == 0)
        return out;
    if (is_native(a, py::dtype::of<float>()))
    {
        if (origin.isZero() && (a.flags() & py::array::c_style))
        {
            // The one copy into the library's storage; then the finiteness check in place.
            std::memcpy(static_cast<void*>(out.data()), a.data(), n * sizeof(Vec3f));
            check_finite_rows(out, name);
            return out;
        }
        read_rows<float>(a, name, origin, out.data());
        return out;
    }
    if (!is_native(a, py::dtype::of<double>()))
        a = as_float64(a);
    read_rows<double>(a, name, origin, out.data());
    return out;
}

std::span<const Vec3d> vec3d_rows(const py::array& array, const char* name,
                                  std::vector<Vec3d>& storage)
{
    py::array a = array;
    check_rows3(a, name, std::nullopt, true);
    const auto n = static_cast<std::size_t>(a.shape(0));
    if (n == 0)
        return {};
    const bool aligned = (a.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) != 0;
    if (is_native(a, py::dtype::of<double>()) && (a.flags() & py::array::c_style) && aligned)
    {
        std::span<const Vec3d> points(static_cast<const Vec3d*>(a.data()), n);
        for (std::size_t i = 0; i < n; ++i)
            if (!points[i].allFinite())
                throw InvalidInput(
                    std::string(name) + "[" + std::to_string(i) +
                    "] is not finite: " + row_text(points[i].x(), points[i].y(), points[i].z()));
        return points;
    }
    storage.resize(n);
    if (is_native(a, py::dtype::of<float>()))
        read_rows<float>(a, name, Vec3d::Zero(), storage.data());
    else
    {
        if (!is_native(a, py::dtype::of<double>()))
            a = as_float64(a);
        read_rows<double>(a, name, Vec3d::Zero(), storage.data());
    }
    return storage;
}

Vec3d first_row(const py::handle& array, const char* name)
{
    py::array a = as_array(array, name);
    check_rows3(a, name, std::nullopt, false);
    if (!is_native(a, py::dtype::of<float>()) && !is_native(a, py::dtype::of<double>()))
        a = as_float64(a);
    Vec3d first;
    if (is_native(a, py::dtype::of<float>()))
    {
        Vec3f f;
        read_rows<float>(a, name, Vec3d::Zero(), &f, 1);
        first = f.cast<double>();
    }
    else
        read_rows<double>(a, name, Vec3d::Zero(), &first, 1);
    return first;
}

namespace {

/// Three finite numbers given as `name` (origin, sensor).
Vec3d vec3_from(const py::handle& value, const std::string& name)
{
    py::array a = as_array(value, name.c_str());
    if (dtype_kind(a) != 'f' && dtype_kind(a) != 'i' && dtype_kind(a) != 'u')
        throw InvalidInput(name + ": expected three real numbers, got dtype " + dtype_text(a));
    if (a.ndim() != 1 || a.shape(0) != 3)
        throw InvalidInput(name + ": expected three numbers, got shape " + shape_text(a));
    auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    const Vec3d o(d.at(0), d.at(1), d.at(2));
    if (!o.allFinite())
        throw InvalidInput(name + " is not finite: " + row_text(o.x(), o.y(), o.z()));
    return o;
}

Vec3d origin_from(const py::handle& origin)
{
    return vec3_from(origin, "origin");
}

/// Checks an N by 3 integer color array; returns it as int64 C order (a view if it was one).
py::array_t<std::int64_t> checked_colors(const py::array& a, std::size_t n)
{
    if (dtype_kind(a) != 'i' && dtype_kind(a) != 'u')
        throw InvalidInput("colors: expected integers 0-255 (uint8), got dtype " + dtype_text(a));
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw InvalidInput("colors: expected an N by 3 array, got shape " + shape_text(a));
    if (static_cast<std::size_t>(a.shape(0)) != n)
        throw InvalidInput("colors: expected " + std::to_string(n) + " rows (one per point), got " +
                           std::to_string(a.shape(0)));
    auto v = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    const std::int64_t* data = v.data();
    for (std::size_t i = 0; i < 3 * n; ++i)
        if (data[i] < 0 || data[i] > 255)
            throw InvalidInput("colors[" + std::to_string(i / 3) + "] has a channel out of " +
                               "0-255: " + std::to_string(data[i]));
    return v;
}

std::vector<Color> colors_from(const py::array& a, std::size_t n)
{
    const py::array_t<std::int64_t> v = checked_colors(a, n);
    const std::int64_t* data = v.data();
    std::vector<Color> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = Color{static_cast<std::uint8_t>(data[3 * i]),
                       static_cast<std::uint8_t>(data[3 * i + 1]),
                       static_cast<std::uint8_t>(data[3 * i + 2])};
    return out;
}

/// Checks an array of N radii; returns them as float64 C order (a view if they were).
py::array_t<double> checked_radii(const py::array& a, std::size_t n)
{
    if (dtype_kind(a) != 'f' && dtype_kind(a) != 'i' && dtype_kind(a) != 'u')
        throw InvalidInput("radii: expected real numbers, got dtype " + dtype_text(a));
    if (a.ndim() != 1)
        throw InvalidInput("radii: expected an array of N numbers, got shape " + shape_text(a));
    if (static_cast<std::size_t>(a.shape(0)) != n)
        throw InvalidInput("radii: expected " + std::to_string(n) +
                           " values (one per point), got " + std::to_string(a.shape(0)));
    auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
    for (std::size_t i = 0; i < n; ++i)
    {
        const double r = d.data()[i];
        if (!std::isfinite(r) || !(r > 0.0))
            throw InvalidInput("radii[" + std::to_string(i) +
                               "] must be positive and finite, got " + std::to_string(r));
    }
    return d;
}

std::vector<float> radii_from(const py::array& a, std::size_t n)
{
    const py::array_t<double> d = checked_radii(a, n);
    std::vector<float> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = static_cast<float>(d.data()[i]);
    return out;
}

py::object optional_rows3f(std::span<const Vec3f> rows, py::handle owner)
{
    if (rows.empty())
        return py::none();
    return rows3_view<float>(rows, owner);
}

py::object optional_colors(std::span<const Color> colors, py::handle owner)
{
    static_assert(sizeof(Color) == 3);
    if (colors.empty())
        return py::none();
    return rows3_view<std::uint8_t>(colors, owner);
}

py::object optional_radii(std::span<const float> radii, py::handle owner)
{
    if (radii.empty())
        return py::none();
    return readonly_view(radii.data(), {static_cast<py::ssize_t>(radii.size())}, owner);
}

py::array world_positions(const PointCloudView& cloud)
{
    std::vector<Vec3d> world(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
        world[i] = cloud.world(i);
    const auto n = static_cast<py::ssize_t>(world.size());
    return owning_array<double>(std::move(world), {n, 3}, true);
}

py::tuple bounds_tuple(const PointCloudView& cloud)
{
    if (cloud.empty())
        throw InvalidInput("bounds: the cloud has no points");
    const Aabb box = cloud.bounds();
    return py::make_tuple(py::array_t<double>(3, box.min.data()),
                          py::array_t<double>(3, box.max.data()));
}

} // namespace

std::shared_ptr<Cloud> make_cloud(const py::handle& positions, const py::handle& normals,
                                  const py::handle& colors, const py::handle& radii,
                                  const py::handle& origin, bool in_place)
{
    PointCloud converted;
    py::array p = as_array(positions, "positions");
    if (!origin.is_none())
        converted.origin = origin_from(origin);
    else if (!is_native(p, py::dtype::of<float>()))
    {
        // float32 positions are taken as they are (origin 0); others are re-centred the way the
        // readers re-centre a file's double coordinates (choose_origin()).
        converted.origin = choose_origin(first_row(p, "positions"));
    }
    check_rows3(p, "positions", std::nullopt, false);
    const auto n = static_cast<std::size_t>(p.shape(0));
    std::vector<py::object> borrowed;
    PointCloudView view;
    const auto rows_in_place = [&](const py::array& a, const char* name) {
        std::span<const Vec3f> rows(static_cast<const Vec3f*>(a.data()), n);
        check_finite_rows(rows, name);
        borrowed.push_back(a);
        return rows;
    };
    if (in_place && converted.origin.isZero() && in_library_layout<float>(p))
        view.positions = rows_in_place(p, "positions");
    else
        converted.positions = vec3f_rows(p, "positions", std::nullopt, converted.origin);
    if (!normals.is_none())
    {
        py::array a = as_array(normals, "normals");
        check_rows3(a, "normals", n, false);
        if (in_place && in_library_layout<float>(a))
            view.normals = rows_in_place(a, "normals");
        else
            converted.normals = vec3f_rows(a, "normals", n);
    }
    if (!colors.is_none())
    {
        py::array a = as_array(colors, "colors");
        if (in_place && in_library_layout<std::uint8_t>(a))
        {
            checked_colors(a, n);
            view.colors = {static_cast<const Color*>(a.data()), n};
            borrowed.push_back(a);
        }
        else
            converted.colors = colors_from(a, n);
    }
    if (!radii.is_none())
    {
        py::array a = as_array(radii, "radii");
        if (in_place && in_library_layout<float>(a))
        {
            checked_radii(a, n);
            view.radii = {static_cast<const float*>(a.data()), n};
            borrowed.push_back(a);
        }
        else
            converted.radii = radii_from(a, n);
    }
    auto cloud = owned_cloud(std::move(converted));
    cloud->borrowed = std::move(borrowed);
    const PointCloud& owned = cloud->owned;
    cloud->view.positions = view.positions.empty() ? owned.positions : view.positions;
    cloud->view.normals = view.normals.empty() ? owned.normals : view.normals;
    cloud->view.colors = view.colors.empty() ? owned.colors : view.colors;
    cloud->view.radii = view.radii.empty() ? owned.radii : view.radii;
    return cloud;
}

std::vector<Triangle> triangles_from(const py::handle& faces, std::size_t vertices)
{
    py::array a = as_array(faces, "faces");
    if (dtype_kind(a) != 'i' && dtype_kind(a) != 'u')
        throw InvalidInput("faces: expected integer vertex indices, got dtype " + dtype_text(a));
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw InvalidInput("faces: expected an F by 3 array, got shape " + shape_text(a));
    if (a.shape(0) == 0)
        throw InvalidInput(
            "faces: the array is empty (0 rows); a shape without faces is a "
            "PointCloud");
    auto v = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    const std::int64_t* data = v.data();
    const auto f = static_cast<std::size_t>(a.shape(0));
    std::vector<Triangle> out(f);
    for (std::size_t i = 0; i < f; ++i)
    {
        for (std::size_t j = 0; j < 3; ++j)
        {
            const std::int64_t index = data[3 * i + j];
            if (index < 0 || static_cast<std::uint64_t>(index) >= vertices)
                throw InvalidInput(
                    "faces[" + std::to_string(i) + "] = (" + std::to_string(data[3 * i]) + ", " +
                    std::to_string(data[3 * i + 1]) + ", " + std::to_string(data[3 * i + 2]) +
                    "): vertex index out of range (the mesh has " + std::to_string(vertices) +
                    " vertices)");
            out[i][j] = static_cast<std::uint32_t>(index);
        }
    }
    return out;
}

void bind_geometry(py::module_& m)
{
    py::class_<Cloud, std::shared_ptr<Cloud>>(
        m, "PointCloud",
        "Level 1 or 2 samples: N positions (float32, relative to `origin`) with optional "
        "normals, colors and influence radii. Immutable; its arrays are read-only views of its "
        "storage (the library's, or the numpy arrays it was made from), alive as long as any of "
        "them or the cloud is.")
        .def(py::init([](const py::object& positions, const py::object& normals,
                         const py::object& colors, const py::object& radii,
                         const py::object& origin, const py::object& sensor) {
                 std::shared_ptr<Cloud> cloud =
                     make_cloud(positions, normals, colors, radii, origin);
                 if (!sensor.is_none())
                 {
                     cloud->owned.sensor = vec3_from(sensor, "sensor");
                     cloud->view.sensor = cloud->owned.sensor;
                 }
                 return cloud;
             }),
             py::arg("positions"), py::kw_only(), py::arg("normals") = py::none(),
             py::arg("colors") = py::none(), py::arg("radii") = py::none(),
             py::arg("origin") = py::none(), py::arg("sensor") = py::none(),
             "PointCloud(positions, *, normals=None, colors=None, radii=None, origin=None, "
             "sensor=None)\n\n"
             "positions: N by 3 real array (float32 or float64, any memory order), N >= 1, "
             "finite. Without `origin`, float32 positions are taken as they are (origin 0) and "
             "other dtypes are re-centred on their first point rounded to whole units, as the "
             "file readers do, so that large (georeferenced) coordinates keep their precision. "
             "With `origin` (3 numbers), positions are stored relative to it.\n"
             "normals: N by 3 real; colors: N by 3 integers 0-255; radii: N positive reals.\n"
             "Arrays already in the library's layout are used in place, without a copy: float32 "
             "positions (origin 0) and normals, uint8 colors and float32 radii, C-contiguous. The "
             "cloud keeps them alive and reads them in every later call, so change them only by "
             "making a new PointCloud. Other dtypes and orders are converted once into the "
             "cloud's own storage.\n"
             "sensor: where the points were seen from (3 numbers, world units), for a depth "
             "image: normals estimated for it face the sensor (`read` sets it for an organized "
             "PCD, from its VIEWPOINT).\n"
             "Raises InvalidInput (a ValueError) for wrong shapes or dtypes, empty positions, "
             "non-finite values or out-of-range colors and radii.")
        .def_property_readonly(
            "positions",
            [](py::object self) {
                return rows3_view<float>(self.cast<const Cloud&>().view.positions, self);
            },
            "N by 3 float32, relative to `origin` (read-only view).")
        .def_property_readonly(
            "normals",
            [](py::object self) {
                return optional_rows3f(self.cast<const Cloud&>().view.normals, self);
            },
            "N by 3 float32 unit normals, or None (read-only view).")
        .def_property_readonly(
            "colors",
            [](py::object self) {
                return optional_colors(self.cast<const Cloud&>().view.colors, self);
            },
            "N by 3 uint8 colors, or None (read-only view).")
        .def_property_readonly(
            "radii",
            [](py::object self) {
                return optional_radii(self.cast<const Cloud&>().view.radii, self);
            },
            "N float32 influence radii in world units, or None (read-only view).")
        .def_property_readonly(
            "origin",
            [](py::object self) {
                return readonly_view(self.cast<const Cloud&>().view.origin.data(), {3}, self);
            },
            "float64 3-vector: world position = origin + position (read-only view).")
        .def_property_readonly(
            "sensor",
            [](const Cloud& c) -> py::object {
                if (!c.view.sensor)
                    return py::none();
                return py::make_tuple(c.view.sensor->x(), c.view.sensor->y(), c.view.sensor->z());
            },
            "Where the points were seen from, (x, y, z) in world units, for a depth image (an "
            "organized PCD's VIEWPOINT, or the constructor's `sensor`); None otherwise.")
        .def(
            "world", [](const Cloud& c) { return world_positions(c.view); },
            "world() -> N by 3 float64 array of world positions (origin + positions), a new "
            "array.")
        .def(
            "bounds", [](const Cloud& c) { return bounds_tuple(c.view); },
            "bounds() -> (min, max): the bounding box in world units, two float64 3-vectors.")
        .def(
            "__len__", [](const Cloud& c) { return c.view.size(); }, "Number of points.")
        .def("__repr__", [](const Cloud& cloud) {
            const PointCloudView& c = cloud.view;
            std::string attributes;
            if (c.has_normals())
                attributes += ", normals";
            if (c.has_colors())
                attributes += ", colors";
            if (c.has_radii())
                attributes += ", radii";
            return "<pointform.PointCloud " + std::to_string(c.size()) + " points" + attributes +
                   ">";
        });

    py::class_<TriMesh, std::shared_ptr<TriMesh>>(
        m, "Mesh",
        "An indexed triangle mesh: vertices (float32, relative to `origin`, with optional "
        "normals, colors, radii) and an F by 3 uint32 face array, counter-clockwise seen from "
        "outside. Immutable; its arrays are read-only views.")
        .def(py::init([](const py::object& vertices, const py::object& faces,
                         const py::object& normals, const py::object& colors,
                         const py::object& origin) {
                 TriMesh mesh;
                 // The library's TriMesh owns its vertices: converted once, never borrowed.
                 mesh.vertices = std::move(
                     make_cloud(vertices, normals, colors, py::none(), origin, false)->owned);
                 mesh.triangles = triangles_from(faces, mesh.vertices.size());
                 return mesh;
             }),
             py::arg("vertices"), py::arg("faces"), py::kw_only(), py::arg("normals") = py::none(),
             py::arg("colors") = py::none(), py::arg("origin") = py::none(),
             "Mesh(vertices, faces, *, normals=None, colors=None, origin=None)\n\n"
             "vertices as PointCloud's positions; faces: F by 3 integer vertex indices, F >= 1, "
             "each in [0, N). Raises InvalidInput (a ValueError) for wrong shapes or dtypes, "
             "empty arrays, non-finite coordinates or indices out of range.")
        .def_property_readonly(
            "vertices",
            [](py::object self) {
                return rows3_view<float>(self.cast<const TriMesh&>().vertices.positions, self);
            },
            "N by 3 float32 vertex positions, relative to `origin` (read-only view).")
        .def_property_readonly(
            "faces",
            [](py::object self) {
                return rows3_view<std::uint32_t>(self.cast<const TriMesh&>().triangles, self);
            },
            "F by 3 uint32 vertex indices (read-only view).")
        .def_property_readonly(
            "normals",
            [](py::object self) {
                return optional_rows3f(self.cast<const TriMesh&>().vertices.normals, self);
            },
            "N by 3 float32 vertex normals, or None (read-only view).")
        .def_property_readonly(
            "colors",
            [](py::object self) {
                return optional_colors(self.cast<const TriMesh&>().vertices.colors, self);
            },
            "N by 3 uint8 vertex colors, or None (read-only view).")
        .def_property_readonly(
            "origin",
            [](py::object self) {
                return readonly_view(self.cast<const TriMesh&>().vertices.origin.data(), {3}, self);
            },
            "float64 3-vector: world position = origin + vertex (read-only view).")
        .def_property_readonly("vertex_count", &TriMesh::vertex_count, "Number of vertices.")
        .def_property_readonly("face_count", &TriMesh::face_count, "Number of triangles.")
        .def(
            "world", [](const TriMesh& mesh) { return world_positions(mesh.vertices); },
            "world() -> N by 3 float64 array of world vertex positions, a new array.")
        .def(
            "points", [](const TriMesh& mesh) { return owned_cloud(mesh.vertices); },
            "points() -> PointCloud: the vertices and their attributes (a copy).")
        .def(
            "bounds", [](const TriMesh& mesh) { return bounds_tuple(mesh.vertices); },
            "bounds() -> (min, max): the vertices' bounding box in world units.")
        .def("__repr__", [](const TriMesh& mesh) {
            return "<pointform.Mesh " + std::to_string(mesh.vertex_count()) + " vertices, " +
                   std::to_string(mesh.face_count()) + " faces>";
        });
}

} // namespace pointform::python
