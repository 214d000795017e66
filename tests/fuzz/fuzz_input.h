#pragma once
// What the fuzz targets share: each input arrives as bytes; a reader that takes a file gets them in a file of
// its own, in a directory made once per process.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace everytouch::fuzz {

// A directory of this process's own, removed at exit.
const std::filesystem::path& scratchDirectory();

// Writes the bytes to `path`, replacing what was there.
void writeFile(const std::filesystem::path& path, std::string_view bytes);

// The input cut at each NUL byte into at most `parts` pieces (the last keeps any further NULs): a target
// that reads several files takes one piece for each.
std::vector<std::string_view> splitParts(const std::uint8_t* data, std::size_t size, std::size_t parts);

}  // namespace everytouch::fuzz
