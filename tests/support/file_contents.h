#pragma once

#include <filesystem>
#include <string>

namespace everytouch::test {

// Everything in the file at `path`, byte for byte; empty when it cannot be read.
std::string fileContents(const std::filesystem::path& path);

}  // namespace everytouch::test
