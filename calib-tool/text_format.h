#pragma once

#include <cstdio>
#include <string>

namespace everytouch::calib {

// printf-style formatting of one short line of the tool's output (a number with its unit, a point, a row of a
// table).
template <typename... Values>
std::string format(const char* pattern, Values... values) {
    char text[256];
    std::snprintf(text, sizeof text, pattern, values...);
    return text;
}

}  // namespace everytouch::calib
