// UTF-8 validation: every text the program takes in (CSV cells, JSON strings from the page) must
// be well-formed UTF-8 before it is stored or written into a file another program reads.
#pragma once

#include <cstddef>
#include <string_view>

namespace uphill {

// Index of the first byte that is not part of well-formed UTF-8 (RFC 3629: no overlong forms,
// no surrogates, nothing above U+10FFFF), or std::string_view::npos when all of `s` is.
std::size_t InvalidUtf8At(std::string_view s);

}  // namespace uphill
