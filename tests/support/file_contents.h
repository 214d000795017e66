#pragma once

#include <filesystem>
#include <string>

namespace everytouch::test {

// Everything in the file at `path`, byte for byte; empty when it cannot be read.
std::string fileContents(const std::filesystem::path& path);

// Replaces the file at `path` with `text`.
void writeText(const std::filesystem::path& path, const std::string& text);

}  // namespace everytouch::test
