// The wording the JSON and CSV readers share, private to base.
#pragma once

#include <cstdint>
#include <string>

namespace camhead::base::detail {

// As an ostream prints a double: 0.5, 1e+06, 1e-09.
std::string show(double v);

// "must be an integer within LO .. HI", for every way of missing it: one
// reason for 8.0, "wide" and a 400-digit number alike, so that none of them
// is told only half of what is wrong.
std::string integer_reason(std::int64_t lo, std::int64_t hi);

} // namespace camhead::base::detail
