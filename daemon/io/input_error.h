#pragma once

#include <stdexcept>
#include <string>

namespace everytouch::io {

// Bad external input (a file, a command-line value, a recording). The message names the input and the field,
// so a user can find and fix it: "rig.yml: camera_matrix: expected a 3x3 matrix, found 3x4".
class InputError : public std::runtime_error {
public:
    InputError(const std::string& input, const std::string& field, const std::string& problem)
        : std::runtime_error(input + ": " + (field.empty() ? "" : field + ": ") + problem) {}
};

}  // namespace everytouch::io
