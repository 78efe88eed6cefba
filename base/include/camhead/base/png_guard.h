// What a PNG file must pass before stb_image sees it. stb_image trusts the
// chunk structure: fuzzing found it reallocating to the length a truncated
// chunk claims (1.3 GB for 41 bytes), copying from a null buffer for an
// empty IDAT chunk, and doubling its inflate buffer for as long as the data
// goes on (2 GiB for 207 bytes). Both PNG readers (the renderer's images and
// the file camera's frames) pass their files through here.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace camhead::base {

// The file without its empty IDAT chunks (the image is the same), once its
// signature is checked and every chunk up to IEND is whole. Empty with
// `error` ("not a readable PNG: ...") otherwise.
[[nodiscard]] std::optional<std::vector<unsigned char>>
png_chunks_checked(std::span<const unsigned char> file, std::string &error);

// Whether the image data of a checked file (png_chunks_checked) inflates to
// no more than the image its header describes. Inflates into a small
// scratch buffer; call it once the header's size has been accepted, since
// the work grows with the image. False with `error` otherwise.
[[nodiscard]] bool png_inflates_within_header(std::span<const unsigned char> checked,
                                              std::string &error);

} // namespace camhead::base
