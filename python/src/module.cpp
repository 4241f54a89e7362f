// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The extension module pointform._pointform: exceptions, threads, and the bind_<module>.cpp
// parts. The library does the work; the bindings convert numpy arrays and release the GIL.

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include "common.h"

#include <exception>

namespace pointform::python {
namespace {

/// The Python exception classes (alive for the process: the module keeps them too).
PyObject* error_class = nullptr;
PyObject* invalid_input_class = nullptr;
PyObject* io_error_class = nullptr;
PyObject* solver_error_class = nullptr;
PyObject* topology_error_class = nullptr;
PyObject* cancelled_class = nullptr;

PyObject* new_exception(py::module_& m, const char* name, const char* doc, PyObject* bases)
{
    const std::string qualified = std::string("pointform.") + name;
    PyObject* cls = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases, nullptr);
    if (cls == nullptr)
        throw py::error_already_set();
    m.add_object(name, py::reinterpret_borrow<py::object>(cls));
    return cls;
}

void bind_errors(py::module_& m)
{
    error_class = new_exception(m, "Error",
                                "Base of every error pointform raises on purpose (a "
                                "RuntimeError).",
                                PyExc_RuntimeError);
    const py::tuple invalid_bases =
        py::make_tuple(py::handle(error_class), py::handle(PyExc_ValueError));
    invalid_input_class =
        new_exception(m, "InvalidInput",
                      "Input that violates a documented precondition: wrong array shapes or "
                      "dtypes, NaN, empty arrays, indices out of range, bad option values (a "
                      "ValueError).",
                      invalid_bases.ptr());
    const py::tuple io_bases = py::make_tuple(py::handle(error_class), py::handle(PyExc_OSError));
    io_error_class = new_exception(m, "IoError",
                                   "A file could not be read or written; the message names the "
                                   "file and, where known, the line or byte offset (an OSError; "
                                   "the file is in its `path` attribute).",
                                   io_bases.ptr());
    solver_error_class = new_exception(
        m, "SolverError", "A numerical method failed to produce a usable answer.", error_class);
    topology_error_class = new_exception(
        m, "TopologyError", "A mesh or graph does not have the topology an algorithm needs.",
        error_class);
    cancelled_class =
        new_exception(m, "Cancelled", "A long-running computation was asked to stop.", error_class);

    py::register_exception_translator([](std::exception_ptr p) {
        try
        {
            if (p)
                std::rethrow_exception(p);
        }
        catch (const InvalidInput& e)
        {
            PyErr_SetString(invalid_input_class, e.what());
        }
        catch (const IoError& e)
        {
            py::object exc = py::reinterpret_borrow<py::object>(io_error_class)(e.what());
            exc.attr("path") = e.path().string();
            PyErr_SetObject(io_error_class, exc.ptr());
        }
        catch (const SolverError& e)
        {
            PyErr_SetString(solver_error_class, e.what());
        }
        catch (const TopologyError& e)
        {
            PyErr_SetString(topology_error_class, e.what());
        }
        catch (const Cancelled& e)
        {
            PyErr_SetString(cancelled_class, e.what());
        }
        catch (const Error& e)
        {
            PyErr_SetString(error_class, e.what());
        }
    });
}

} // namespace

py::object to_python(const nlohmann::json& value)
{
    switch (value.type())
    {
        case nlohmann::json::value_t::object:
        {
            py::dict out;
            for (const auto& [key, item] : value.items())
                out[py::str(key)] = to_python(item);
            return out;
        }
        case nlohmann::json::value_t::array:
        {
            py::list out;
            for (const auto& item : value)
                out.append(to_python(item));
            return out;
        }
        case nlohmann::json::value_t::string:
            return py::str(value.get_ref<const std::string&>());
        case nlohmann::json::value_t::boolean:
            return py::bool_(value.get<bool>());
        case nlohmann::json::value_t::number_integer:
            return py::int_(value.get<std::int64_t>());
        case nlohmann::json::value_t::number_unsigned:
            return py::int_(value.get<std::uint64_t>());
        case nlohmann::json::value_t::number_float:
            return py::float_(value.get<double>());
        case nlohmann::json::value_t::null:
        case nlohmann::json::value_t::binary:
        case nlohmann::json::value_t::discarded:
            break;
    }
    return py::none();
}

} // namespace pointform::python

PYBIND11_MODULE(_pointform, m)
{
    namespace pf = pointform::python;
    m.doc() =
        "pointform: multiresolution modeling from point samples (points -> oriented surfels "
        "-> signed field -> marching cubes -> semi-regular mesh). numpy in, numpy out: arrays "
        "of returned objects are read-only views of the library's storage; every heavy call "
        "releases the GIL.";
    m.attr("__version__") = PF_VERSION;
    pf::bind_errors(m);
    m.def("thread_count", &pointform::thread_count,
          "thread_count() -> int: threads the library's parallel loops use.");
    m.def(
        "set_thread_count",
        [](int threads) {
            if (threads < 0)
                throw pointform::InvalidInput(
                    "set_thread_count: threads must be 0 (all cores) "
                    "or positive, got " +
                    std::to_string(threads));
            pointform::set_thread_count(threads);
        },
        pybind11::arg("threads"),
        "set_thread_count(threads): threads for the parallel loops of later calls made from "
        "this Python thread (OpenMP keeps the setting per thread); 0 = all cores (or "
        "OMP_NUM_THREADS). Results do not depend on it.");
    pf::bind_geometry(m);
    pf::bind_io(m);
    pf::bind_hermite(m);
    pf::bind_implicit(m);
    pf::bind_polygonize(m);
    pf::bind_multires(m);
    pf::bind_metrics(m);
}
