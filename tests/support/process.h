#pragma once

#include <string>
#include <vector>

namespace everytouch::test {

struct ProcessResult {
    int exitCode = -1;  // the exit status, or 128 + signal number
    std::string out;    // everything written to stdout
    std::string err;    // everything written to stderr
};

// Runs a program to completion with the given arguments, capturing its output. Fails the test if it cannot
// start.
ProcessResult runProcess(const std::vector<std::string>& argv);

}  // namespace everytouch::test
