// A PNG decoded once by libpng's simplified API to find out whether it is whole, before
// OpenImageIO reads it: OpenImageIO 2.4 leaves libpng's default error handler in place,
// which prints "libpng error: ..." on stderr next to our own one-line message.
#pragma once

#include <cstddef>
#include <string>

namespace speculum {

// True when `bytes` start with the PNG signature.
bool is_png(const unsigned char* bytes, std::size_t size);

// "" when libpng decodes the whole image, else its message (one line). Images of more than
// `max_pixels` pixels are refused before any pixel buffer is reserved.
std::string png_problem(const unsigned char* bytes, std::size_t size, long long max_pixels);

}  // namespace speculum
