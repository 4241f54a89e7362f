// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

namespace pointform::cli {

/// Blocks of 4 MiB and more allocated from now on ask for transparent huge pages (see
/// large_pages.cpp): for commands whose large arrays are all written densely.
void ask_for_huge_pages();

} // namespace pointform::cli
