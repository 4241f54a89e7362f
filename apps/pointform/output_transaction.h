// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/error.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace pointform::cli {

/// \brief All-or-nothing output for a command that writes one or more files.
///
/// Each output is first written to a temporary file beside its target (same directory, same
/// extension, so writers that pick a format from the extension still do); commit() then renames
/// every temporary into place. A failure while staging removes the temporaries and leaves every
/// target untouched; a failure while committing puts back the targets already replaced (from a
/// hard link made before the rename), so pre-existing files keep their bytes either way.
/// Destroying an uncommitted transaction removes its temporaries.
class OutputTransaction
{
public:
    OutputTransaction() = default;
    ~OutputTransaction();
    OutputTransaction(const OutputTransaction&) = delete;
    OutputTransaction& operator=(const OutputTransaction&) = delete;

    /// \brief Writes one output through `write(temporary_path)`, staged until commit().
    /// \throw IoError naming `target` (not the temporary) if it is a directory, its directory is
    ///        missing or unwritable, or the write fails; InvalidInput if `target` is already
    ///        an output of this transaction
    template <typename Write>
    void stage(const std::filesystem::path& target, Write&& write)
    {
        const std::filesystem::path temp = reserve(target);
        try
        {
            std::forward<Write>(write)(temp);
        }
        catch (const IoError& e)
        {
            discard_last();
            throw IoError(target, strip_path(e, temp));
        }
        catch (...)
        {
            discard_last();
            throw;
        }
    }

    /// \brief Renames every staged file into place. \throw IoError naming the target that
    /// could not be replaced (the others are then as they were)
    void commit();

private:
    struct Staged
    {
        std::filesystem::path target;
        std::filesystem::path temp;
    };

    std::filesystem::path reserve(const std::filesystem::path& target);
    void discard_last();
    static std::string strip_path(const IoError& e, const std::filesystem::path& temp);

    std::vector<Staged> staged_;
    bool committed_ = false;
};

} // namespace pointform::cli

namespace pointform::cli {

/// \brief Writes a command's only output through an OutputTransaction.
template <typename Write>
void write_output(const std::filesystem::path& target, Write&& write)
{
    OutputTransaction transaction;
    transaction.stage(target, std::forward<Write>(write));
    transaction.commit();
}

} // namespace pointform::cli
