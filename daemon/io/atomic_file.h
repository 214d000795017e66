#pragma once

#include <filesystem>
#include <string_view>

namespace everytouch::io {

// Replaces `path` with `contents` so that readers see either the old or the new file, never a partial one:
// write a temporary file in the same directory, fsync it, rename it over `path`, fsync the directory.
// Throws std::system_error naming the path.
void writeFileAtomically(const std::filesystem::path& path, std::string_view contents);

}  // namespace everytouch::io
