#pragma once
// What the fuzz targets share: each input arrives as bytes; a reader that takes a file gets them in a file of
// its own, in a directory made once per process.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "io/input_error.h"

namespace everytouch::fuzz {

// A directory of this process's own, removed at exit.
const std::filesystem::path& scratchDirectory();

// A recording directory in the scratch directory, made once: frames/, masks/ and a 640 x 480 pattern.png of
// ones, the projector size of the targets' rig.yml. The targets write the files they fuzz into it.
const std::filesystem::path& recordingSkeleton();

// Writes the bytes to `path`, replacing what was there.
void writeFile(const std::filesystem::path& path, std::string_view bytes);

// Writes the input to a file `name` in the scratch directory and has `read` read it: a reader may refuse it
// only with io::InputError; any other exception escapes, a finding.
template <typename Read>
void readAsFile(const char* name, const std::uint8_t* data, std::size_t size, Read&& read) {
    const std::filesystem::path path = scratchDirectory() / name;
    writeFile(path, std::string_view(reinterpret_cast<const char*>(data), size));
    try {
        read(path);
    } catch (const io::InputError&) {
    }
}

// The input cut at each NUL byte into at most `parts` pieces (the last keeps any further NULs): a target
// that reads several files takes one piece for each.
std::vector<std::string_view> splitParts(const std::uint8_t* data, std::size_t size, std::size_t parts);

}  // namespace everytouch::fuzz
