// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/implicit/field.h"

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace pointform {

/// \file
/// \brief The modeling language: a scene is a field built from scans, primitives, operators and
/// transforms (§4.2), written as a small expression language that people can read and that the
/// `pointform model` and `pointform morph` commands take inline or as a file.
///
/// Example (a scene file; numbers are in the scans' units):
///
///     # saw a slot through the bunny and stick a ball behind its head
///     let bunny = scan("bun_zipper.ply")
///     let ball  = sphere([-0.03, 0.15, 0], 0.02)
///     let slot  = box([-0.1, 0.1, -0.005], [0.1, 0.2, 0.005], rounded = 0.002)
///     difference(smooth_union(bunny, ball, radius = 0.01), slot)
///
/// Grammar (EBNF; `#` starts a comment that runs to the end of the line):
///
///     scene     = { sep } [ statement { sep { sep } statement } ] { sep } ;
///     sep       = newline | ";" ;
///     statement = [ "let" ] name "=" expr      (* a binding *)
///               | expr ;                       (* the result *)
///     expr      = number | vector | string | name | call ;
///     call      = name "(" [ arg { "," arg } [ "," ] ] ")" ;
///     arg       = [ name "=" ] expr ;          (* positional, or keyword *)
///     vector    = "[" expr "," expr "," expr "]" ;   (* three numbers *)
///     number    = [ "+" | "-" ] ( digits [ "." [ digits ] ] | "." digits )
///                 [ ( "e" | "E" ) [ "+" | "-" ] digits ] ;
///     string    = '"' { any character but '"' and newline, or \" or \\ } '"' ;
///     name      = letter_or_underscore { letter_or_underscore | digit } ;
///
/// Inside parentheses and brackets newlines are plain white space, so an expression may span
/// lines. Calls and vectors nest at most 256 deep in the text, and a field at most 256 operators
/// and transforms deep counting through bindings; a binding is one node however often it is
/// named (a field named more than once is a SharedField: evaluated once per batch of points). The
/// scene's result is its last statement: an expression, or a binding named `result`. A scene has
/// exactly one result; every earlier statement is a binding. A binding may hold any value (a
/// number, a vector, a string or a field) and is visible to the statements after it; a name is
/// bound once, and may not be `let` or a function's name. Positional arguments come before keyword
/// arguments; a keyword argument names a parameter (e.g. `sphere(radius = 1, center = [0, 0, 0])`).
/// Values have four types: number, vector ([x, y, z]), string and field; a parameter accepts one
/// type (scale's factor: number or vector).
///
/// Functions (parameters with a default are optional; `...` takes any number of fields):
///
///     scan(path)                                  a point field: the samples of a file, as
///                                                 the load_scan callback makes them
///     sphere(center, radius)
///     box(min, max, rounded = 0)                  axis-aligned, edges rounded by `rounded`
///     oriented_box(center, half_extents, axis = [0,0,1], degrees = 0, rounded = 0)
///     cylinder(a, b, radius)
///     cone(a, b, radius_a, radius_b = 0)
///     torus(center, axis, major_radius, minor_radius)
///     half_space(point, normal)                   the solid behind the plane (unbounded)
///     union(a, b, ...)                            min       (Table 2)
///     intersection(a, b, ...)                     max
///     difference(a, b, ...)                       a minus b and the rest: max(f_a, −f_b, …)
///     smooth_union(a, b, radius)                  fillet of blend radius `radius`
///     smooth_intersection(a, b, radius)
///     smooth_difference(a, b, radius)
///     blend(a, ..., range, kind = "linear", beta = 2)
///                                                 Table 3: kind "linear", "hyperbolic" or
///                                                 "super_elliptic"; range = 1/α, input units
///     offset(a, distance)                         f − d: outwards for d > 0
///     shell(a, thickness)                         a hollow shell |f| − t/2
///     morph(a, b, t)                              (1 − t)·f_a + t·f_b, t in [0, 1]
///     translate(a, offset)
///     rotate(a, axis, degrees, center = [0,0,0])  right-handed about axis through center
///     scale(a, factor, center = [0,0,0])          factor a number or [sx, sy, sz]
///
/// The operators and primitives are those of primitives.h, operators.h and transform.h, with
/// their conventions and bounds. Every error is an InvalidInput whose message starts with
/// `source:line:column:` and says what was expected and what was found, e.g.
/// `scene.pf:3:17: expected ',' or ')' after argument 2 of sphere, found 'x'`; an unknown
/// function, keyword or name comes with the closest known one ("did you mean 'sphere'?").
/// Columns count characters (UTF-8 code points) from 1.

/// \brief Makes the field of a scan; `path` is already resolved (see SceneOptions).
using ScanLoader = std::function<std::shared_ptr<const Field>(const std::string& path)>;

struct SceneOptions
{
    /// The name of the text in error messages: a file's path, or e.g. "expression".
    std::string source_name = "expression";
    /// Relative scan paths are resolved against this directory; empty = the current directory.
    std::filesystem::path base_directory;
    /// Loads `scan(path)` inputs, once per distinct resolved path. Unset: scan() is an error.
    ScanLoader load_scan;
};

/// \brief A parsed and built scene.
struct Scene
{
    /// The scene's result.
    std::shared_ptr<const Field> field;
    /// The scans the result uses (resolved paths, in the order they were loaded; each once).
    /// A scan bound to a name that the result never uses is not loaded.
    std::vector<std::string> scans;
};

/// \brief Parses a scene and builds its field.
///
/// Three passes: the whole text is parsed (syntax errors), then every statement is checked
/// (names, argument counts and types, parameter ranges) before any scan is loaded, and finally
/// the result's field is built, loading each scan it uses once.
/// \throw InvalidInput for a malformed or invalid scene, a parameter out of range or a scan
///        file that does not exist, with `source:line:column:` and what was expected; what
///        load_scan throws (an InvalidInput gets the `scan` call's location prefixed, an
///        IoError for a file that cannot be read passes through: it names the file).
[[nodiscard]] Scene parse_scene(std::string_view text, const SceneOptions& options = {});

/// \brief Reads a scene file: source_name is `path` and relative scans resolve against its
/// directory. \throw IoError if the file cannot be read; otherwise as parse_scene
[[nodiscard]] Scene read_scene(const std::filesystem::path& path, ScanLoader load_scan = {});

/// \brief How a command-line argument that may be a scene file or a scene expression is taken:
/// as a file if a file of that name exists, otherwise as an expression.
[[nodiscard]] bool looks_like_file(std::string_view argument);

/// \brief One line per function, "name(parameters)", for help texts.
[[nodiscard]] std::string scene_function_summary();

} // namespace pointform
