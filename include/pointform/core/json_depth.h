// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <string_view>

namespace pointform {

/// \brief Whether JSON text nests arrays and objects deeper than `limit` (brackets inside
/// strings do not count). Checked before parsing, so that no input can make a recursive parser,
/// or the destructor of a deep value, recurse far. Does not validate the text otherwise.
[[nodiscard]] bool json_nests_deeper_than(std::string_view text, std::size_t limit) noexcept;

} // namespace pointform
