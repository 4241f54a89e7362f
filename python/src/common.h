// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// What the bind_<module>.cpp files share: numpy views of library storage (read-only, owned by
// the Python object that owns the storage), numpy inputs converted in one pass, and the
// Python-side objects that are not library types (Hierarchy).

#pragma once

#include "pointform/core/error.h"
#include "pointform/core/progress.h"
#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <nlohmann/json.hpp>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

namespace pointform::python {

namespace py = pybind11;

/// \brief A read-only numpy array over `data` (C order, `shape`), kept alive by `owner`: no
/// copy. An empty shape gets a fresh empty array.
template <class T>
py::array readonly_view(const T* data, std::vector<py::ssize_t> shape, py::handle owner,
                        bool writeable = false)
{
    std::vector<py::ssize_t> strides(shape.size());
    py::ssize_t stride = sizeof(T);
    for (std::size_t i = shape.size(); i-- > 0;)
    {
        strides[i] = stride;
        stride *= shape[i];
    }
    py::array out(py::dtype::of<T>(), shape, strides, data, owner);
    if (!writeable)
        py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return out;
}

/// \brief A numpy array of Scalar that owns `values` (moved into a capsule, no copy): for
/// results computed on demand, the caller's to keep (writeable) or the owner's (read-only). T is
/// Scalar or a packed vector of Scalars (Vec3d).
template <class Scalar, class T>
py::array owning_array(std::vector<T> values, std::vector<py::ssize_t> shape,
                       bool writeable = false)
{
    static_assert(sizeof(T) % sizeof(Scalar) == 0);
    auto* heap = new std::vector<T>(std::move(values));
    py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return readonly_view(reinterpret_cast<const Scalar*>(heap->data()), std::move(shape), owner,
                         writeable);
}

/// \brief Raises Python's KeyboardInterrupt (the interrupt that a progress callback took).
[[noreturn]] inline void raise_keyboard_interrupt()
{
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
}

/// \brief Runs `work(progress)` with the GIL released, where `progress` is a ProgressCallback
/// for the library's options that lets Ctrl-C stop the work: when the library reports progress
/// from the calling thread (signals reach Python's main thread only), it takes the GIL and runs
/// Python's signal handlers; a KeyboardInterrupt asks the library to stop (it throws Cancelled)
/// and is raised once the work has unwound. It is raised too where the work returns although
/// it was asked to stop (a step that ends early on a false progress instead of throwing): the
/// handler has taken the signal, and the caller must still see it. Results do not depend on it.
template <class Work>
auto run_interruptible(Work&& work)
{
    auto interrupted = std::make_shared<std::atomic<bool>>(false);
    const std::thread::id caller = std::this_thread::get_id();
    ProgressCallback progress = [interrupted, caller](std::string_view, double) {
        if (std::this_thread::get_id() != caller)
            return true;
        const py::gil_scoped_acquire gil;
        if (PyErr_CheckSignals() != 0)
        {
            PyErr_Clear();
            interrupted->store(true);
            return false;
        }
        return true;
    };
    try
    {
        auto result = [&] {
            const py::gil_scoped_release release;
            return work(progress);
        }();
        if (interrupted->load())
            raise_keyboard_interrupt();
        return result;
    }
    catch (const Cancelled&)
    {
        if (!interrupted->load())
            throw;
        raise_keyboard_interrupt();
    }
}

/// \brief An N by 3 array of 3-vectors of T (Eigen vectors or std::array), as a view; `rows` is
/// a contiguous range (std::vector or std::span).
template <class T, class Rows>
py::array rows3_view(const Rows& rows, py::handle owner)
{
    using V = std::remove_cvref_t<decltype(*rows.data())>;
    static_assert(sizeof(V) == 3 * sizeof(T), "rows must be three packed scalars");
    return readonly_view(reinterpret_cast<const T*>(rows.data()),
                         {static_cast<py::ssize_t>(rows.size()), 3}, owner);
}

/// \brief Positions (or normals) from an N by 3 array of any real dtype and memory order, in
/// one pass: a float32 C-contiguous array is copied as it is into the library's storage; others
/// are converted element by element. With `origin` the values are taken relative to it (in
/// double precision, then rounded to float).
/// \throw InvalidInput naming `name` for a wrong shape or dtype, no rows (unless allow_empty), a
///        non-finite value, or a row count other than `rows` (when given)
std::vector<Vec3f> vec3f_rows(const py::handle& array, const char* name,
                              std::optional<std::size_t> rows = std::nullopt,
                              const Vec3d& origin = Vec3d::Zero(), bool allow_empty = false);

/// \brief Query points from an M by 3 array, in double precision: a float64 C-contiguous array
/// is used in place (no copy, `storage` untouched); others are converted once into `storage`.
/// \throw InvalidInput as vec3f_rows()
std::span<const Vec3d> vec3d_rows(const py::array& array, const char* name,
                                  std::vector<Vec3d>& storage);

/// \brief The first row of an N by 3 real array, in double precision (for the origin).
Vec3d first_row(const py::handle& array, const char* name);

/// \brief A numpy array (or anything numpy.asarray takes) as a py::array, without copying.
py::array as_array(const py::handle& object, const char* name);

/// \brief A point cloud as Python holds it (pointform.PointCloud): the arrays the library made
/// or the bindings converted, owned here, and numpy arrays used in place, kept alive here.
/// Library calls read `view`, which points into both; so a Cloud is made once, by make_shared,
/// and never copied or moved. Its last reference must go with the GIL held (the numpy arrays).
struct Cloud
{
    PointCloud owned;
    std::vector<py::object> borrowed; ///< numpy arrays `view` reads in place
    PointCloudView view;

    explicit Cloud(PointCloud cloud) : owned(std::move(cloud)), view(owned) {}
    Cloud(const Cloud&) = delete;
    Cloud& operator=(const Cloud&) = delete;
    Cloud(Cloud&&) = delete;
    Cloud& operator=(Cloud&&) = delete;
    ~Cloud() = default;
};

/// \brief A Cloud owning what the library made.
inline std::shared_ptr<Cloud> owned_cloud(PointCloud cloud)
{
    return std::make_shared<Cloud>(std::move(cloud));
}

/// \brief A point cloud from numpy arrays (the PointCloud constructor): with `in_place`, arrays
/// already in the library's layout (float32 positions and normals N by 3 C-contiguous with
/// origin 0, uint8 colors N by 3 and float32 radii, contiguous) are checked and used in place;
/// others are converted once into the cloud's own storage.
std::shared_ptr<Cloud> make_cloud(const py::handle& positions, const py::handle& normals,
                                  const py::handle& colors, const py::handle& radii,
                                  const py::handle& origin, bool in_place = true);

/// \brief A report of the library (report_json()) as Python objects: objects as dicts, arrays
/// as lists, numbers, strings, booleans and None; the same figures the CLI's --json prints.
py::object to_python(const nlohmann::json& value);

/// \brief Triangles from an F by 3 integer array, each index below `vertices`.
std::vector<Triangle> triangles_from(const py::handle& faces, std::size_t vertices);

/// \brief A multiresolution hierarchy as Python sees it: the MultiresMesh, the report of how it
/// was made (a dict; None when loaded from a file), and the per-level faces and world positions,
/// made on first use and kept so that the arrays handed out stay views.
struct Hierarchy
{
    MultiresMesh mesh;
    py::object report = py::none();

    std::mutex cache_mutex;
    std::vector<std::optional<std::vector<Triangle>>> faces;
    std::optional<std::vector<Vec3d>> world;

    explicit Hierarchy(MultiresMesh m, py::object r = py::none())
        : mesh(std::move(m)), report(std::move(r)), faces(mesh.level_count())
    {}
    /// \throw InvalidInput for a level that does not exist (negative ones count from the end)
    [[nodiscard]] std::size_t level_index(long long level) const;
};

/// \brief The faces of a hierarchy's level and the world positions, computed once (the GIL
/// released while they are made).
const std::vector<Triangle>& hierarchy_faces(Hierarchy& h, std::size_t level);
const std::vector<Vec3d>& hierarchy_world(Hierarchy& h);

void bind_geometry(py::module_& m);
void bind_io(py::module_& m);
void bind_hermite(py::module_& m);
void bind_implicit(py::module_& m);
void bind_polygonize(py::module_& m);
void bind_multires(py::module_& m);
void bind_metrics(py::module_& m);

} // namespace pointform::python
