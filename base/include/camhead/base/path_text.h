// Whether a string from outside (a board, a scene, an output URI, the
// command line) can name a file. The C library ends a path at its first NUL,
// so "victim\0.y4m" opens "victim": another file than the one named, and
// one the partial-file rule never sees. Other control characters name files
// nobody meant (a pasted newline, an escape sequence in a terminal). Every
// path a user writes goes through here before it is used, and the caller
// names the field.
#pragma once

#include <string>
#include <string_view>

namespace camhead::base {

// Empty when `text` is a usable path; else why not, in words for the field's
// message: "holds a NUL character (\u0000) at position 6".
[[nodiscard]] std::string path_text_problem(std::string_view text);

// `text` for a message: every control character as \u00XX, so that a NUL
// does not end the message where it stands.
[[nodiscard]] std::string printable_text(std::string_view text);

} // namespace camhead::base
