// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/multires/deformation.h"
#include "pointform/multires/details.h"
#include "pointform/multires/lattice.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pointform {

/// \file
/// \brief The JSON files of `pointform deform` (docs/deform.md): an edit (handles, targets,
/// region) and a lattice. Shared by every front end, so the command line, Python and the viewer
/// read them alike.
///
/// Edit: {"level": j, "handles": [{"vertices": [ids], "translate": [x, y, z]} or {"vertices":
/// [ids], "matrix": [16 numbers, row-major 4 × 4]}, …], "region": {"vertices": [ids]} or
/// {"ball": {"center": [x, y, z], "radius": r}} or {"box": {"min": [...], "max": [...]}}}; no
/// region: the whole level. A handle may give a "ball" or a "box" in place of "vertices": the
/// level's vertices there (DeformHandle::within()). Lattice: {"min": [...], "max": [...],
/// "degree": [l, m, n], "level": j, "control_points": [[x, y, z], …]} ((l + 1)(m + 1)(n + 1)
/// points, x fastest, world coordinates); "level" may be left out (0).
///
/// Every problem is an InvalidInput naming the source: text that is not JSON (with its line and
/// column), nesting deeper than 16, a key that is not one of the above, a value of the wrong
/// type, a vertex id that is not an integer in [0, 2³² − 1), a number that is not finite, a
/// handle with both or neither of translate and matrix, a region or handle with more than one
/// kind of vertex set. The
/// checks that need the hierarchy (ids of the level, handles inside the region, the lattice's
/// size) are made by MultiresDeformer and validate_lattice().

/// \brief A lattice and the level it deforms.
struct LatticeEdit
{
    std::size_t level = 0;
    Lattice lattice;
};

/// \brief What `pointform deform` does: one edit, or one lattice in a mode.
struct DeformRequest
{
    std::optional<MultiresEdit> edit;
    std::optional<LatticeEdit> lattice;
    LatticeMode lattice_mode = LatticeMode::Details;
};

/// \brief What deform_hierarchy() did, with the figures every front end reports.
struct DeformOutcome
{
    std::string mode; ///< "edit", "lattice (details)" or "lattice (plain)"
    Predictor predictor = Predictor::Midpoint;
    double diagonal = 0.0; ///< of the input's bounding box
    DeformReport deformation;
    double normal_tolerance = 0.1;         ///< as detail_statistics()
    std::vector<DetailLevelStats> details; ///< of the input, per level 1 … J
};

/// \brief Deforms `mesh` as `request` asks (deform() or apply_lattice()), with the statistics of
/// the input's details and its diagonal: the one call behind the CLI's and Python's deform.
/// \throw InvalidInput unless exactly one of edit and lattice is set, or as deform() and
/// apply_lattice()
DeformOutcome deform_hierarchy(MultiresMesh& mesh, const DeformRequest& request);

/// \brief The largest edit or lattice file read: 256 MiB.
inline constexpr std::size_t max_edit_file_bytes = std::size_t{256} << 20;

/// \brief Parses an edit; `source` names it in errors. \throw InvalidInput
[[nodiscard]] MultiresEdit parse_multires_edit(std::string_view text, const std::string& source);

/// \brief Parses a lattice; `source` names it in errors. \throw InvalidInput
[[nodiscard]] LatticeEdit parse_lattice(std::string_view text, const std::string& source);

/// \brief Reads and parses an edit file.
/// \throw IoError if the file cannot be read or is larger than max_edit_file_bytes;
///        InvalidInput as parse_multires_edit()
[[nodiscard]] MultiresEdit read_multires_edit(const std::filesystem::path& path);

/// \brief Reads and parses a lattice file. \throw IoError, InvalidInput as read_multires_edit()
[[nodiscard]] LatticeEdit read_lattice(const std::filesystem::path& path);

} // namespace pointform
