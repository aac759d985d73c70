#include "io/utf8.hpp"

#include "internal/utf8.hpp"

namespace uphill {

std::size_t InvalidUtf8At(std::string_view s) { return internal::InvalidUtf8At(s); }

}  // namespace uphill
